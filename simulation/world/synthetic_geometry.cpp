#include "simulation/world/synthetic_geometry.hpp"

#include <cmath>
#include <limits>

namespace orthoflow::simulation {
namespace {

constexpr std::uint32_t TABLE_RGB = 0xFF8B5A2BU;
constexpr std::uint32_t FLOOR_RGB = 0xFF707070U;
constexpr std::uint32_t ROBOT_RGB = 0xFF303438U;  // the JACO's carbon-fibre dark grey

/// Whether the ray can come within @p r of @p c (d need not be unit length).
bool near_sphere(const Vec3& o, const Vec3& d, const Vec3& c, double r) {
  const Vec3 oc = c - o;
  const double along = dot(oc, d) / dot(d, d);
  const Vec3 closest = o + along * d - c;
  return dot(closest, closest) <= r * r;
}

SurfaceHit finish(const SurfaceHit& best, double t_max) {
  return best.t >= t_max ? SurfaceHit{} : best;
}

}  // namespace

SceneGeometry::SceneGeometry(const Scene& scene) noexcept
    : table_(table_frame(scene.table)), spec_(scene.table) {
  for (const PlacedObject& o : scene.objects) {
    if (count_ == poses_.size()) { break; }
    Pose& p = poses_[count_++];
    p.model = &o.model;
    p.label = OBJECT_LABEL_BASE + o.id;
    const double c = std::cos(o.yaw), s = std::sin(o.yaw);
    p.ax = c * table_.right + s * table_.forward;
    p.ay = -s * table_.right + c * table_.forward;
    p.az = table_.normal;
    p.origin = table_.point(o.table_x, o.table_y, o.base_m);
    const double h = o.model.height;
    p.sphere_center = p.origin + (h / 2) * p.az;
    p.sphere_radius = std::hypot(o.model.footprint_radius, h / 2) + 0.01;
  }
  for (const BodyCapsule& c : scene.robot) {
    if (robot_count_ == robot_.size()) { break; }
    robot_[robot_count_++] = c;
  }
}

void SceneGeometry::cast_robot(const Vec3& o, const Vec3& d, double t_min,
                               SurfaceHit& best) const noexcept {
  for (std::size_t i = 0; i < robot_count_; ++i) {
    const BodyCapsule& c = robot_[i];
    Hit h;
    h.t = best.t;
    if (intersect_capsule(c.a, c.b, c.radius, o, d, t_min, h)) {
      best.t = h.t;
      best.normal = h.normal;
      best.label = LABEL_ROBOT;
      best.rgb = ROBOT_RGB;
    }
  }
}

void SceneGeometry::cast_objects(const Vec3& o, const Vec3& d, double t_min,
                                 SurfaceHit& best) const noexcept {
  for (std::size_t i = 0; i < count_; ++i) {
    const Pose& p = poses_[i];
    if (!near_sphere(o, d, p.sphere_center, p.sphere_radius)) { continue; }
    const Vec3 rel = o - p.origin;
    const Vec3 ol{dot(rel, p.ax), dot(rel, p.ay), dot(rel, p.az)};
    const Vec3 dl{dot(d, p.ax), dot(d, p.ay), dot(d, p.az)};
    Hit h;
    h.t = best.t;
    bool any = false;
    for (std::size_t k = 0; k < p.model->part_count; ++k) {
      any |= intersect(p.model->parts[k], ol, dl, t_min, h);
    }
    if (any) {
      best.t = h.t;
      best.normal = h.normal[0] * p.ax + h.normal[1] * p.ay + h.normal[2] * p.az;
      best.label = p.label;
      best.rgb = p.model->rgb;
    }
  }
}

SurfaceHit SceneGeometry::cast(const Vec3& o, const Vec3& d, double t_min,
                               double t_max) const noexcept {
  SurfaceHit best;
  best.t = t_max;
  const double denom = dot(table_.normal, d);
  if (std::fabs(denom) > 1e-12) {
    const double t_table = -(dot(table_.normal, o) + table_.d) / denom;
    const Vec3 q = o + t_table * d - table_.center;
    if (t_table > t_min && t_table < best.t &&
        std::fabs(dot(q, table_.right)) <= spec_.width_m / 2 &&
        std::fabs(dot(q, table_.forward)) <= spec_.depth_m / 2) {
      best = SurfaceHit{t_table, table_.normal, LABEL_TABLE, TABLE_RGB};
    }
    const double t_floor = -(dot(table_.normal, o) + table_.d + spec_.floor_drop_m) / denom;
    if (spec_.floor_drop_m > 0.0 && t_floor > t_min && t_floor < best.t) {
      best = SurfaceHit{t_floor, table_.normal, LABEL_FLOOR, FLOOR_RGB};
    }
  }
  cast_objects(o, d, t_min, best);
  cast_robot(o, d, t_min, best);
  return finish(best, t_max);
}

float measure_depth(const SurfaceHit& hit, const Vec3& dir, const Vec3& projector,
                    const SceneGeometry& geo, const RenderOptions& options, const DepthTable& table,
                    core::Rng& rng) noexcept {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const KinectDepthParams& k = options.depth;
  const Vec3 p = hit.t * dir;  // dir has z = 1, so t is the depth
  if (p[2] < k.min_range_m || p[2] > k.max_range_m) { return nan; }
  const double cos_view =
      std::fabs(dot(hit.normal, dir)) / std::sqrt(dot(hit.normal, hit.normal) * dot(dir, dir));
  if (cos_view < options.grazing_cos) { return nan; }
  // The projector must see the point too: anything on the segment projector -> p casts a shadow.
  if (geo.cast(projector, p - projector, 1e-6, 1.0 - 1e-6).found()) { return nan; }
  const double raw = depth_to_raw(p[2], k) + k.sigma_raw * rng.normal();
  const double rounded = std::nearbyint(raw);
  if (!(rounded >= 0.0 && rounded < static_cast<double>(KINECT_NO_READING))) { return nan; }
  const float z = table[static_cast<std::size_t>(rounded)];
  const bool in_range =
      z >= static_cast<float>(k.min_range_m) && z <= static_cast<float>(k.max_range_m);
  return in_range ? z : nan;
}

}  // namespace orthoflow::simulation
