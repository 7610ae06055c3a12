#include "simulation/world/table_world.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <utility>

namespace orthoflow::simulation {

namespace {

/// @p p in table coordinates: x along the table's right, y along its forward, up along its normal.
Vec3 to_table(const TableFrame& t, const Vec3& p) noexcept {
  const Vec3 d = p - t.center;
  return {dot(d, t.right), dot(d, t.forward), dot(d, t.normal)};
}

/// The object's extent along the line through @p tool (sensor frame) in direction @p u: from where
/// the line enters its solids to where it leaves them, or nullopt when it misses them.
std::optional<double> chord(const TableFrame& t, const PlacedObject& o, const Vec3& tool,
                            const Vec3& u) noexcept {
  const std::array<double, 16> m = object_pose(t, o);
  const Vec3 ax{m[0], m[4], m[8]}, ay{m[1], m[5], m[9]}, az{m[2], m[6], m[10]};
  const Vec3 d = tool - Vec3{m[3], m[7], m[11]};
  const Vec3 q{dot(d, ax), dot(d, ay), dot(d, az)};
  Vec3 v{dot(u, ax), dot(u, ay), dot(u, az)};
  const double n = std::sqrt(dot(v, v));
  if (!(n > 1e-9)) return std::nullopt;
  v = (1.0 / n) * v;
  constexpr double REACH_M = 0.5;  // both ends start this far out, outside any object
  Hit in, out;
  for (std::size_t k = 0; k < o.model.part_count; ++k) {
    (void)intersect(o.model.parts[k], q - REACH_M * v, v, 0.0, in);
    (void)intersect(o.model.parts[k], q + REACH_M * v, (-1.0) * v, 0.0, out);
  }
  if (!in.found() || !out.found()) return std::nullopt;
  const double width = 2.0 * REACH_M - in.t - out.t;
  return width > 0.0 ? std::optional<double>(width) : std::nullopt;
}

}  // namespace

TableWorld::TableWorld(Scene scene) : scene_(std::move(scene)), frame_(table_frame(scene_.table)) {}

int TableWorld::find(std::uint32_t id) const noexcept {
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
    if (scene_.objects[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

Vec3 TableWorld::centre(std::size_t index) const noexcept {
  const PlacedObject& o = scene_.objects[index];
  return frame_.point(o.table_x, o.table_y, o.base_m + 0.5 * o.model.height);
}

bool TableWorld::inside(const PlacedObject& o, const Vec3& local) const noexcept {
  const double dx = local[0] - o.table_x;
  const double dy = local[1] - o.table_y;
  const double r = o.model.footprint_radius + GRIP_SLACK_M;
  return dx * dx + dy * dy <= r * r && local[2] >= o.base_m - GRIP_SLACK_M &&
         local[2] <= o.base_m + o.model.height + GRIP_SLACK_M;
}

int TableWorld::nearest_inside(const Vec3& local) const noexcept {
  int best = -1;
  double best_d2 = 0.0;
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
    const PlacedObject& o = scene_.objects[i];
    if (!inside(o, local)) continue;
    const double dx = local[0] - o.table_x, dy = local[1] - o.table_y;
    if (best < 0 || dx * dx + dy * dy < best_d2) {
      best = static_cast<int>(i);
      best_d2 = dx * dx + dy * dy;
    }
  }
  return best;
}

std::optional<double> TableWorld::grip_width(const Vec3& tool, const Vec3& closing) const noexcept {
  if (held_ >= 0) return held_width_;
  const int i = nearest_inside(to_table(frame_, tool));
  if (i < 0) return std::nullopt;
  return chord(frame_, scene_.objects[static_cast<std::size_t>(i)], tool, closing);
}

bool open_container(Category c) noexcept { return c == Category::MUG || c == Category::BOWL; }

void TableWorld::update(const Vec3& tool, double opening_m, const HandAxes& hand) noexcept {
  const int before = held_;
  step(tool, opening_m, &hand[1]);
  if (held_ < 0) {
    have_hand_ = false;
    tilt_deg_ = 0.0;
    return;
  }
  if (held_ != before || !have_hand_) {  // just taken: upright, fixed in the hand from now on
    up_in_hand_ = {dot(hand[0], frame_.normal), dot(hand[1], frame_.normal),
                   dot(hand[2], frame_.normal)};
    have_hand_ = true;
    spilled_ = false;
  }
  Vec3 up{};
  for (std::size_t k = 0; k < 3; ++k) up = up + up_in_hand_[k] * hand[k];
  const double c = std::clamp(dot(up, frame_.normal) / std::sqrt(dot(up, up)), -1.0, 1.0);
  tilt_deg_ = std::acos(c) * 180.0 / std::numbers::pi;
  const PlacedObject& o = scene_.objects[static_cast<std::size_t>(held_)];
  if (!spilled_ && tilt_deg_ > SPILL_TILT_DEG && open_container(o.model.category)) {
    spilled_ = true;
    ++spills_;
  }
  if (tilt_deg_ > DROP_TILT_DEG) {  // it slips out of the fingers
    ++drops_;
    release();
    have_hand_ = false;
    tilt_deg_ = 0.0;
  }
}

void TableWorld::update(const Vec3& tool, double opening_m) noexcept {
  step(tool, opening_m, nullptr);
}

void TableWorld::step(const Vec3& tool, double opening_m, const Vec3* closing_axis) noexcept {
  const Vec3 local = to_table(frame_, tool);
  // The first call is no motion (NaN compares false).
  const bool closing = opening_m < last_opening_ - 1e-4;
  const bool opening = opening_m > last_opening_ + 1e-4;
  last_opening_ = opening_m;
  if (held_ >= 0) {
    if (opening && opening_m > grip_opening_ + RELEASE_MARGIN_M) {
      release();
      return;
    }
    grip_opening_ = std::min(grip_opening_, opening_m);  // the fingers squeeze it
    PlacedObject& o = scene_.objects[static_cast<std::size_t>(held_)];
    o.table_x = local[0] + grip_offset_[0];
    o.table_y = local[1] + grip_offset_[1];
    o.base_m = std::max(0.0, local[2] + grip_offset_[2]);
    return;
  }
  if (!closing) return;
  // Closing fingers hold the nearest object whose cylinder holds the tool point, once they reach
  // its width between them (where a rigid object stops them): its chord along the closing axis,
  // or without the hand's orientation its footprint diameter.
  const int best = nearest_inside(local);
  if (best < 0) return;
  const PlacedObject& candidate = scene_.objects[static_cast<std::size_t>(best)];
  const std::optional<double> width =
      closing_axis != nullptr ? chord(frame_, candidate, tool, *closing_axis)
                              : std::optional<double>(2.0 * candidate.model.footprint_radius);
  if (!width || opening_m > *width + GRIP_CONTACT_M) return;
  held_ = best;
  held_width_ = *width;
  grip_opening_ = opening_m;
  const PlacedObject& o = scene_.objects[static_cast<std::size_t>(best)];
  grip_offset_ = {o.table_x - local[0], o.table_y - local[1], o.base_m - local[2]};
}

void TableWorld::release() noexcept {
  const auto index = static_cast<std::size_t>(held_);
  held_ = -1;
  PlacedObject& o = scene_.objects[index];
  const double half_w = 0.5 * scene_.table.width_m, half_d = 0.5 * scene_.table.depth_m;
  if (std::fabs(o.table_x) > half_w || std::fabs(o.table_y) > half_d) {
    scene_.objects.erase(scene_.objects.begin() + static_cast<std::ptrdiff_t>(index));
    ++fallen_;
    return;
  }
  o.base_m = 0.0;
}

bool TableWorld::move_object(std::size_t index, double x, double y) noexcept {
  if (index >= scene_.objects.size() || static_cast<int>(index) == held_) return false;
  scene_.objects[index].table_x = x;
  scene_.objects[index].table_y = y;
  return true;
}

}  // namespace orthoflow::simulation
