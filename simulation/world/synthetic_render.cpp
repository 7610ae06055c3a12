// Renders a Scene into an organized Kinect-like cloud: one primary ray per depth pixel through the
// pinhole model, a shadow ray to the IR projector, then the depth model (kinect_depth_model.hpp).
#include <cmath>
#include <limits>

#include "core/assert.hpp"
#include "simulation/world/synthetic_geometry.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::simulation {
namespace {

/// Sizes @p out and its fields only when they differ, so a warm cloud is reused without allocating.
void prepare(const DepthIntrinsics& in, kernels::PointCloud& out) {
  if (out.width() != in.width || out.height() != in.height) { out.resize(in.width, in.height); }
  out.add_field(kernels::Field::RGB);
  out.add_field(kernels::Field::LABEL);
  out.remove_field(kernels::Field::NORMALS);
}

}  // namespace

void render_scene(const Scene& scene, const RenderOptions& options, core::Rng& rng,
                  kernels::PointCloud& out) {
  OF_ENFORCE(scene.objects.size() <= MAX_SCENE_OBJECTS, "render_scene: too many objects");
  OF_ENFORCE(scene.robot.size() <= MAX_SCENE_CAPSULES, "render_scene: too many robot capsules");
  const DepthIntrinsics& in = options.intrinsics;
  prepare(in, out);
  const SceneGeometry geo(scene);
  const DepthTable table = make_depth_table(options.depth);
  const Vec3 camera{0.0, 0.0, 0.0};
  const Vec3 projector{options.projector_x_m, 0.0, 0.0};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto xs = out.x(), ys = out.y(), zs = out.z();
  auto rgb = out.rgb(), label = out.label();
  std::size_t i = 0;
  for (std::uint32_t v = 0; v < in.height; ++v) {
    for (std::uint32_t u = 0; u < in.width; ++u, ++i) {
      const Vec3 dir{(u - in.cx) / in.fx, (v - in.cy) / in.fy, 1.0};
      const SurfaceHit hit = geo.cast(camera, dir, 1e-9, 1e9);
      const float z =
          hit.found() ? measure_depth(hit, dir, projector, geo, options, table, rng) : nan;
      rgb[i] = hit.rgb;
      if (std::isnan(z)) {
        xs[i] = ys[i] = zs[i] = nan;
        label[i] = LABEL_NONE;
        continue;
      }
      // The sensor reports depth on the pixel grid: the point lies on the pixel's ray at depth z.
      xs[i] = static_cast<float>(dir[0] * z);
      ys[i] = static_cast<float>(dir[1] * z);
      zs[i] = z;
      label[i] = hit.label;
    }
  }
}

}  // namespace orthoflow::simulation
