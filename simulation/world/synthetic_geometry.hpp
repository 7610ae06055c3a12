#pragma once
// Ray casting over a Scene (internal to the synthetic scene generator): the table rectangle, the
// floor, every object and the robot's body, with per-object bounding spheres to skip most rays
// cheaply.
#include <array>

#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::simulation {

/// The nearest surface along a ray.
struct SurfaceHit {
  double t = 1e300;
  Vec3 normal{};
  std::uint32_t label = LABEL_NONE;
  std::uint32_t rgb = 0;
  [[nodiscard]] bool found() const noexcept { return t < 1e299; }
};

class SceneGeometry {
 public:
  explicit SceneGeometry(const Scene& scene) noexcept;
  /// Nearest hit with t in (t_min, t_max) along o + t d.
  [[nodiscard]] SurfaceHit cast(const Vec3& o, const Vec3& d, double t_min,
                                double t_max) const noexcept;

 private:
  struct Pose {
    const ObjectModel* model = nullptr;
    Vec3 origin{}, ax{}, ay{}, az{};
    Vec3 sphere_center{};
    double sphere_radius = 0.0;
    std::uint32_t label = 0;
  };
  void cast_objects(const Vec3& o, const Vec3& d, double t_min, SurfaceHit& best) const noexcept;

  void cast_robot(const Vec3& o, const Vec3& d, double t_min, SurfaceHit& best) const noexcept;

  TableFrame table_;
  TableSpec spec_;
  std::array<Pose, MAX_SCENE_OBJECTS> poses_{};
  std::size_t count_ = 0;
  std::array<BodyCapsule, MAX_SCENE_CAPSULES> robot_{};
  std::size_t robot_count_ = 0;
};

/// Depth (metres) the sensor reports for @p hit seen along @p dir: NaN in projector shadows, out of
/// range and at grazing angles; otherwise the true depth with disparity noise, quantised to the
/// 11-bit raw disparity and converted back through @p table.
[[nodiscard]] float measure_depth(const SurfaceHit& hit, const Vec3& dir, const Vec3& projector,
                                  const SceneGeometry& geo, const RenderOptions& options,
                                  const DepthTable& table, core::Rng& rng) noexcept;

}  // namespace orthoflow::simulation
