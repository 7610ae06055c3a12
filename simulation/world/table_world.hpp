#pragma once
/// @file
/// @brief A tabletop scene that reacts to a gripper (issue 21, item 6): the closed-loop world of
/// `orthoflow demo`. The caller moves the gripper (its tool point and finger opening, in the
/// sensor frame) every arm cycle; the world applies one documented contact rule, and the scene it
/// renders shows where everything now is. No physics engine:
/// - **Grasp:** when the fingers are closing and narrower than an object's footprint diameter while
///   the tool point is inside that object's bounding cylinder (footprint circle plus GRIP_SLACK_M,
///   bottom to top plus GRIP_SLACK_M), the object is held (the nearest such). Fingers closing with
///   the tool point anywhere else hold nothing (a miss leaves the object where it was).
/// - **Holding:** a held object keeps its offset from the tool point (in table coordinates) and
///   stays upright (its yaw does not change: the planner keeps a grasped object parallel to the
///   table); it never goes below the table.
/// - **Release:** when the fingers open RELEASE_MARGIN_M wider than the narrowest they closed to
///   while holding it, it drops straight down and rests on the table (stacking on another object is
///   not modelled); one released beyond the table's edge falls to the floor and leaves the scene
///   (counted).
/// - Not modelled: the hand or the arm pushing an object, objects pushing each other.
/// Deterministic; no allocation in update().
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::simulation {

/// @brief Slack of the grasp test around an object's bounding cylinder.
inline constexpr double GRIP_SLACK_M = 0.01;
/// @brief Fingers this much wider than where they took an object let it go.
inline constexpr double RELEASE_MARGIN_M = 0.001;

class TableWorld {
 public:
  explicit TableWorld(Scene scene);

  /// @brief The contact rule for the gripper at @p tool (sensor frame) with its fingers @p
  /// opening_m apart. Call every arm cycle.
  void update(const Vec3& tool, double opening_m) noexcept;

  /// @brief The scene as it is now (objects where the world put them; the robot's capsules are the
  /// caller's to set). @note objects that fell off the table are not in it.
  [[nodiscard]] const Scene& scene() const noexcept { return scene_; }
  /// @brief The robot's body in view, drawn with the next render (at most MAX_SCENE_CAPSULES).
  [[nodiscard]] std::vector<BodyCapsule>& robot() noexcept { return scene_.robot; }
  [[nodiscard]] const TableFrame& table() const noexcept { return frame_; }

  /// @brief Index into scene().objects of the object held, or -1.
  [[nodiscard]] int held() const noexcept { return held_; }
  /// @brief Index of the object with id @p id, or -1 (fell off, or never there).
  [[nodiscard]] int find(std::uint32_t id) const noexcept;
  /// @brief The centre of object @p index (half its height above its bottom), sensor frame.
  [[nodiscard]] Vec3 centre(std::size_t index) const noexcept;
  /// @brief Objects that fell off the table.
  [[nodiscard]] std::size_t fallen() const noexcept { return fallen_; }

  /// @brief Moves object @p index to table position (@p x, @p y) on the table (a person moving it;
  /// a held object is not moved). @return false if it is held or the index is out of range.
  bool move_object(std::size_t index, double x, double y) noexcept;

 private:
  [[nodiscard]] bool inside(const PlacedObject& o, const Vec3& local) const noexcept;
  void release() noexcept;

  Scene scene_;
  TableFrame frame_{};
  int held_ = -1;
  Vec3 grip_offset_{};  ///< held object's (x, y, base) minus the tool's (x, y, up), table frame
  double grip_opening_ = 0.0;  ///< the narrowest opening since the held object was taken
  double last_opening_ = std::numeric_limits<double>::quiet_NaN();  ///< the previous update's
  std::size_t fallen_ = 0;
};

}  // namespace orthoflow::simulation
