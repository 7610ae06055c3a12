#pragma once
/// @file
/// @brief A tabletop scene that reacts to a gripper (issue 21, item 6): the closed-loop world of
/// `orthoflow demo`. The caller moves the gripper (its tool point and finger opening, in the
/// sensor frame) every arm cycle; the world applies one documented contact rule, and the scene it
/// renders shows where everything now is. No physics engine:
/// - **Grasp:** when the fingers are closing and reach an object's width between them (within
///   GRIP_CONTACT_M) while the tool point is inside that object's bounding cylinder (footprint
///   circle plus GRIP_SLACK_M, bottom to top plus GRIP_SLACK_M), the object is held (the nearest
///   such). Its width is the chord of its solids along the fingers' closing axis through the tool
///   point (the neck of a bottle grasped from above), or, when the caller gives no hand
///   orientation, its footprint diameter. Fingers closing with the tool point anywhere else, or
///   along a line that misses the solids, hold nothing (a miss leaves the object where it was).
/// - **Rigid:** the object the fingers close on stops them at that width (grip_width(); the
///   caller stops the simulated hand there, SimJacoArm::set_finger_stop), so a hand that closes on
///   nothing reaches its goal and one that closes on an object stalls short of it.
/// - **Holding:** a held object keeps its offset from the tool point (in table coordinates); it is
///   drawn upright (its yaw does not change) and never goes below the table. When the caller gives
///   the hand's orientation, the object turns with the hand: its tilt (the angle of its up axis
///   from the table's normal) is followed every update. An open container (mug, bowl) tilted past
///   SPILL_TILT_DEG spills (counted once per carry); anything tilted past DROP_TILT_DEG slips out
///   of the fingers and falls where it is (onto the table, or off its edge).
/// - **Release:** when the fingers open RELEASE_MARGIN_M wider than the narrowest they closed to
///   while holding it, it drops straight down and rests on the table (stacking on another object is
///   not modelled); one released beyond the table's edge falls to the floor and leaves the scene
///   (counted).
/// - Not modelled: the hand or the arm pushing an object, objects pushing each other, an object
///   toppling (a dropped one lands upright).
/// Deterministic; no allocation in update().
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::simulation {

/// @brief Slack of the grasp test around an object's bounding cylinder.
inline constexpr double GRIP_SLACK_M = 0.01;
/// @brief Fingers within this of an object's footprint diameter touch it.
inline constexpr double GRIP_CONTACT_M = 0.003;
/// @brief An open container tilted further than this spills (degrees from upright).
inline constexpr double SPILL_TILT_DEG = 30.0;
/// @brief Anything tilted further than this slips out of the fingers.
inline constexpr double DROP_TILT_DEG = 60.0;
/// @brief The hand's orientation in the sensor frame: its three axes (the rotation's columns).
using HandAxes = std::array<Vec3, 3>;
/// @brief Whether @p c holds liquid open to the air (it spills when tilted): mug, bowl.
[[nodiscard]] bool open_container(Category c) noexcept;

/// @brief Fingers this much wider than where they took an object let it go.
inline constexpr double RELEASE_MARGIN_M = 0.001;

class TableWorld {
 public:
  explicit TableWorld(Scene scene);

  /// @brief The contact rule for the gripper at @p tool (sensor frame) with its fingers @p
  /// opening_m apart. Call every arm cycle.
  void update(const Vec3& tool, double opening_m) noexcept;
  /// @brief The same, with the hand's orientation: a held object turns with the hand (its tilt is
  /// followed; it spills or drops past the limits).
  void update(const Vec3& tool, double opening_m, const HandAxes& hand) noexcept;

  /// @brief The width between the fingers at @p tool (sensor frame) closing along @p closing
  /// that stops them: the held object's width where it was taken, else the chord along the closing
  /// axis through the tool point of the object closing fingers would take there (the grasp rule's),
  /// or nullopt when nothing is between them. @note Never allocates.
  [[nodiscard]] std::optional<double> grip_width(const Vec3& tool,
                                                 const Vec3& closing) const noexcept;

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
  /// @brief The held object's tilt now (degrees from upright; 0 when none is held, or no hand
  /// orientation was given).
  [[nodiscard]] double held_tilt_deg() const noexcept { return tilt_deg_; }
  /// @brief Carries in which an open container spilled, and objects that slipped out tilted.
  [[nodiscard]] std::size_t spills() const noexcept { return spills_; }
  [[nodiscard]] std::size_t drops() const noexcept { return drops_; }

  /// @brief Moves object @p index to table position (@p x, @p y) on the table (a person moving it;
  /// a held object is not moved). @return false if it is held or the index is out of range.
  bool move_object(std::size_t index, double x, double y) noexcept;

 private:
  [[nodiscard]] bool inside(const PlacedObject& o, const Vec3& local) const noexcept;
  /// The contact rule; @p closing_axis (sensor frame) null: widths are footprint diameters.
  void step(const Vec3& tool, double opening_m, const Vec3* closing_axis) noexcept;
  /// The nearest object whose bounding cylinder holds @p local (table coordinates), or -1.
  [[nodiscard]] int nearest_inside(const Vec3& local) const noexcept;
  void release() noexcept;

  Scene scene_;
  TableFrame frame_{};
  int held_ = -1;
  Vec3 grip_offset_{};  ///< held object's (x, y, base) minus the tool's (x, y, up), table frame
  double grip_opening_ = 0.0;  ///< the narrowest opening since the held object was taken
  double last_opening_ = std::numeric_limits<double>::quiet_NaN();  ///< the previous update's
  std::size_t fallen_ = 0;
  double held_width_ = 0.0;  ///< the held object's width between the fingers when taken
  bool have_hand_ = false;   ///< the held object's up axis in the hand's frame is known
  Vec3 up_in_hand_{};        ///< the table's normal in the hand's axes at the grasp
  double tilt_deg_ = 0.0;
  bool spilled_ = false;  ///< this carry's spill is counted
  std::size_t spills_ = 0;
  std::size_t drops_ = 0;
};

}  // namespace orthoflow::simulation
