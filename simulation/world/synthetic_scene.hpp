#pragma once
/// @file
/// @brief Synthetic Kinect v1 tabletop frames with per-pixel ground truth: the embedded default
/// input.
///
/// What is simulated: a finite table rectangle 0.7-1.2 m in front of the sensor, tilted 30-60
/// degrees to the optical axis, a floor 0.72 m below it, objects of 12 categories standing on the
/// table; exact ray casting (occlusion), the projector-camera baseline (NaN in occlusion shadows),
/// range limits, dropouts at grazing angles, disparity noise and 11-bit quantisation
/// (kinect_depth_model.hpp). What is not: speckle and IR texture, lens distortion, multipath, the
/// colour camera's offset (colours are per-surface constants), table legs and clutter.
///
/// Labels: 0 = no reading, 1 = table, 2 = floor, 3 = the robot's body, OBJECT_LABEL_BASE + id = the
/// object with that id (make_scene numbers objects by their index; sequences keep an object's id
/// while it lives). Determinism: all randomness comes from core::Rng; the same seed gives the same
/// bytes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/rng.hpp"
#include "kernels/point_cloud.hpp"
#include "simulation/world/kinect_depth_model.hpp"
#include "simulation/world/object_catalog.hpp"

namespace orthoflow::simulation {

inline constexpr std::uint32_t LABEL_NONE = 0;
inline constexpr std::uint32_t LABEL_TABLE = 1;
inline constexpr std::uint32_t LABEL_FLOOR = 2;
inline constexpr std::uint32_t LABEL_ROBOT = 3;  ///< the robot's body (Scene::robot)
inline constexpr std::uint32_t OBJECT_LABEL_BASE = 100;
/// @brief Most objects one scene holds (rendering keeps per-object state in a fixed array).
inline constexpr std::uint32_t MAX_SCENE_OBJECTS = 64;

/// @brief The table: a rectangle centred on the optical axis at `distance_m`, its plane making
/// `tilt_rad` with the optical axis (pi/2 = looking straight down).
struct TableSpec {
  double distance_m = 1.0;
  double tilt_rad = 0.785;
  double width_m = 1.2;        ///< along the sensor's x axis
  double depth_m = 0.8;        ///< along the table, away from the sensor
  double floor_drop_m = 0.72;  ///< <= 0: no floor
};

/// @brief One object placed on the table: position in table coordinates (x right, y away), yaw.
struct PlacedObject {
  ObjectModel model;
  double table_x = 0.0;
  double table_y = 0.0;
  double yaw = 0.0;
  std::uint32_t id = 0;  ///< its pixels get label OBJECT_LABEL_BASE + id (make_scene: the index)
  double base_m = 0.0;   ///< height of its bottom above the table (> 0: it lies on another object)
};

/// @brief Derived geometry of a table in the sensor frame (x right, y down, z forward).
struct TableFrame {
  Vec3 normal{};   ///< unit, pointing up (towards the sensor side)
  Vec3 right{};    ///< unit, the table's x axis
  Vec3 forward{};  ///< unit, the table's y axis (away from the sensor)
  Vec3 center{};
  double d = 0.0;  ///< plane: dot(normal, p) + d = 0
  [[nodiscard]] Vec3 point(double x, double y, double up = 0.0) const {
    return center + x * right + y * forward + up * normal;
  }
};

[[nodiscard]] TableFrame table_frame(const TableSpec& table) noexcept;

/// @brief Most robot-body capsules one scene holds.
inline constexpr std::size_t MAX_SCENE_CAPSULES = 32;

/// @brief A part of the robot's body in the sensor frame: the segment [a, b] swept by a sphere of
/// @p radius (a == b: a sphere). An arm's links are rendered as these (label LABEL_ROBOT).
struct BodyCapsule {
  Vec3 a{};
  Vec3 b{};
  double radius = 0.0;
};

/// @brief Everything needed to render a frame, which is also its ground truth.
struct Scene {
  TableSpec table;
  std::vector<PlacedObject> objects;
  std::vector<BodyCapsule> robot;  ///< the robot's body in view (at most MAX_SCENE_CAPSULES)
};

/// @brief How scenes are drawn at random.
struct SceneConfig {
  std::uint32_t objects = 6;
  bool touching = false;               ///< place objects in touching pairs
  std::vector<Category> categories{};  ///< empty: the SCENE_CATEGORY_COUNT scene categories
  std::uint32_t instances_per_category = 5;
  bool floor = true;  ///< render a floor below the table
  /// Boxes in stacks of two: every object is a box, and every second one lies on the previous
  /// (a box at most 0.85 of its size, roughly centred, turned by up to 20 degrees; none if no box
  /// instance is that small). Overrides touching.
  bool stacked = false;
};

/// @brief Pose of an object in the sensor frame: columns x, y, z axes, then the position (row-major
/// 4x4).
[[nodiscard]] std::array<double, 16> object_pose(const TableFrame& table,
                                                 const PlacedObject& object) noexcept;

/// @brief The table rectangle's corners in the sensor frame (near-left, near-right, far-right,
/// far-left).
[[nodiscard]] std::array<Vec3, 4> table_corners(const TableSpec& table) noexcept;

/// @brief Draws a table and up to config.objects non-overlapping objects (fewer if they do not fit
/// after a bounded number of attempts). Footprints are circles around each object's axis: apart,
/// they never interpenetrate; with `touching`, every second object's circle touches the previous
/// one's (a real contact for round objects). Deterministic in @p seed. @pre config.objects <=
/// MAX_SCENE_OBJECTS
[[nodiscard]] Scene make_scene(const SceneConfig& config, std::uint64_t seed);

/// @brief Sensor and rendering options.
struct RenderOptions {
  DepthIntrinsics intrinsics{};
  KinectDepthParams depth{};
  double projector_x_m = 0.075;  ///< the IR projector sits this far along +x from the camera
  double grazing_cos = 0.08;     ///< returns at a flatter angle than this are dropped
};

/// @brief Renders @p scene into @p out (organized width x height, RGB and LABEL fields), drawing
/// the noise from @p rng. Allocates only when @p out is not yet that size with those fields, so a
/// warm cloud is refilled without touching the heap. Sets no FrameInfo (the caller stamps frames).
/// @pre scene.objects.size() <= MAX_SCENE_OBJECTS, scene.robot.size() <= MAX_SCENE_CAPSULES.
/// Deterministic; not thread-safe on one @p rng.
void render_scene(const Scene& scene, const RenderOptions& options, core::Rng& rng,
                  kernels::PointCloud& out);

/// @brief Object id of a label, or -1 for table, floor and no reading.
[[nodiscard]] inline int object_of_label(std::uint32_t label) noexcept {
  return label >= OBJECT_LABEL_BASE ? static_cast<int>(label - OBJECT_LABEL_BASE) : -1;
}

}  // namespace orthoflow::simulation
