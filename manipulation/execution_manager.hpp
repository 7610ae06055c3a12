#pragma once
/// @file
/// @brief The execution manager (issue 21, item 3; thesis chapter 2): one pick-and-place as a
/// finite-state machine over primitive operators (go to the initial pose, open, pre-grasp,
/// approach, close, lift, carry, place, release, retreat), each with a timeout and a success
/// check from the arm's state and from perception, and aborts that back away safely.
///
/// The manager decides; it never talks to the arm itself. Each step() gets the arm's newest state
/// and perception's newest view of the target and the other objects, and returns at most one arm
/// request to submit (the caller also feeds the arm's watchdog every cycle, and stops feeding it
/// when the manager is done). So it runs the same against the real arm, the simulated one, or a
/// plain sequence of states in a test. No allocation, no blocking, bounded work per step;
/// deterministic.
///
/// Aborts (every one logged with its reason):
/// - the arm reports a fault or its emergency stop, or refuses a command (the safety layer said
///   no): stop, nothing more;
/// - before the object is held (pre-grasp, approach, close): perception older than the limit (the
///   stale-perception interlock), the target gone or moved, an obstacle near the path, a phase's
///   timeout: stop, then back away to the pre-grasp pose (open the hand first if it was closing);
/// - with the object held (lift, carry, place): stale perception, an obstacle or a timeout: stop
///   and hold; the hand is never opened over an unknown place;
/// - after the lift, a target that did not rise with the hand (GRASP_MISSED): open, back away.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include <Eigen/Geometry>

#include "drivers/jaco/jaco_controller.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"

namespace orthoflow::manipulation {

/// @brief The primitive operators, in order, and the end states.
enum class Phase : std::uint8_t {
  IDLE,
  GO_INITIAL,
  OPEN,
  PRE_GRASP,
  APPROACH,
  CLOSE,
  LIFT,
  CARRY,
  PLACE,
  RELEASE,
  RETREAT,
  DONE,
  BACKING_AWAY,  ///< an abort's retreat to the pre-grasp pose
  ABORTED,
};
inline constexpr std::size_t PHASE_COUNT = 14;
[[nodiscard]] const char* to_string(Phase phase) noexcept;

/// @brief Why a job stopped before DONE (NONE while it runs or when it succeeded).
enum class AbortReason : std::uint8_t {
  NONE,
  TIMEOUT,           ///< a phase took longer than its limit
  PERCEPTION_STALE,  ///< the newest objects are older than the limit
  TARGET_LOST,       ///< the target's track is gone
  TARGET_MOVED,      ///< the target moved away from where the plan put it
  OBSTACLE,          ///< another object near the hand's path
  ARM_FAULT,
  ARM_ESTOP,
  REFUSED,        ///< the arm (its safety layer) refused a command
  GRASP_MISSED,   ///< after the lift the target had not risen with the hand
  STOP_REQUESTED  ///< request_stop()
};
[[nodiscard]] const char* to_string(AbortReason reason) noexcept;

/// @brief One pick and place, all in joint space, planned beforehand (make_pick_place_job).
struct PickPlaceJob {
  std::uint32_t track_id = 0;
  Eigen::Vector3d target_centre = Eigen::Vector3d::Zero();  ///< base frame, when planned
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< the table's normal (base frame, unit)
  drivers::jaco::JointAngles initial{}, pre_grasp{}, grasp{}, lift{}, carry{}, place{}, retreat{};
  /// A way in from above (add_way_in_from_above): PRE_GRASP first goes to above_pre_grasp, the
  /// pre-grasp pose raised along the table's normal, then down to the pre-grasp.
  bool via_above = false;
  drivers::jaco::JointAngles above_pre_grasp{};
  /// A way out from above (add_rise_first): GO_INITIAL first raises the hand from where the arm
  /// was when the job was planned (risen), then goes to the initial pose.
  bool rise_first = false;
  drivers::jaco::JointAngles risen{};
  /// A way round (add_way_round): CARRY first goes to aside, the carry's midpoint moved sideways
  /// along the table at the carry height, then on to above the place.
  bool via_aside = false;
  drivers::jaco::JointAngles aside{};
  double open_fingers = 0.0;   ///< the model's units (0 open)
  double close_fingers = 0.0;  ///< the model's units
  /// Fingers stalled past this value are on the object (the close phase's grasp); stalled before
  /// it, they were blocked right where they started (JobOptions::touch_travel_m from the open
  /// hand).
  double touch_fingers = 0.0;
  double lift_m = 0.10;  ///< how far the lift raises the hand (the grasp check uses half)
};

/// @brief Limits. Timeouts are per phase, indexed by Phase.
struct ExecutionLimits {
  std::array<std::int64_t, PHASE_COUNT> timeout_ns{0,               // IDLE
                                                   30'000'000'000,  // GO_INITIAL
                                                   5'000'000'000,   // OPEN
                                                   20'000'000'000,  // PRE_GRASP
                                                   10'000'000'000,  // APPROACH
                                                   5'000'000'000,   // CLOSE
                                                   10'000'000'000,  // LIFT
                                                   20'000'000'000,  // CARRY
                                                   10'000'000'000,  // PLACE
                                                   5'000'000'000,   // RELEASE
                                                   10'000'000'000,  // RETREAT
                                                   0,               // DONE
                                                   20'000'000'000,  // BACKING_AWAY
                                                   0};              // ABORTED
  std::int64_t perception_max_age_ns = 300'000'000;  ///< the stale-perception interlock
  std::int64_t target_lost_ns = 500'000'000;         ///< the target unseen this long is lost
  /// The target has moved when its centre is farther than this from the plan along the table, or
  /// has risen more than this. A centre that sinks is the hand hiding a partial view's top as it
  /// comes down on it (it sank 6 cm under a top grasp on a bottle), not a move.
  double target_moved_m = 0.03;
  double obstacle_clearance_m = 0.05;  ///< another object's sphere this near the path blocks it
  double joint_tolerance_deg = 1.0;    ///< a joint goal is reached within this
  /// A finger goal is reached within this (model units): 2 % of the JACO2's range (its controller
  /// calls 1 % of it reached).
  double finger_tolerance = 130.0;
  double approach_speed = 0.3;  ///< of the speed cap: approach, close, lift, place, backing
  /// A hand that closes all the way to its goal (JobOptions::close_to_m: closed) held
  /// nothing: a rigid object stalls the fingers short of it (fingers_blocked). The close phase then
  /// aborts as a missed grasp. false only where nothing can stop the fingers: a simulated arm
  /// without a world between them (`orthoflow task run --sim`).
  bool fingers_must_meet_the_object = true;
};

/// @brief The arm's newest state, as the manager needs it.
struct ArmInput {
  drivers::jaco::JointAngles joints{};
  std::array<double, 3> fingers{};
  bool idle = true;  ///< no motion under way (the controller's IDLE)
  /// The fingers stopped short of their last goal against something: a grasped object.
  bool fingers_blocked = false;
  bool fault = false;
  bool estop = false;
};

/// @brief The manager's view of the driver's snapshot @p s. No allocation.
[[nodiscard]] ArmInput arm_input(const drivers::jaco::ArmSnapshot& s) noexcept;

/// @brief Another object, as a sphere in the base frame.
struct Obstacle {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// @brief Perception's newest view. @p others: every other tracked object of that frame.
struct PerceptionInput {
  std::int64_t stamp_ns = 0;  ///< time of the frame the objects come from (0: none yet)
  bool target_seen = false;   ///< the target's track is in that frame
  /// The target is not seen because the hand is where it is (the camera sees the hand, the body
  /// filter removes what is near it): not evidence that it is gone, so the lost timer waits.
  bool target_hidden = false;
  Eigen::Vector3d target_centre = Eigen::Vector3d::Zero();  ///< base frame
  std::span<const Obstacle> others{};
};

/// @brief True if a sphere of @p others comes nearer than @p clearance_m to the segment [@p from,
/// @p to] (the manager's path check; a planner uses it to pick a grasp whose approach is free).
[[nodiscard]] bool segment_blocked(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                   std::span<const Obstacle> others, double clearance_m) noexcept;

/// @brief Tool points sampled along a joint-space move to check its path: the controller moves
/// every joint on one synchronised profile (drivers/jaco/jaco_motion.hpp), so the tool follows the
/// forward kinematics of the straight joint-space segment, a curve that can sag far from the
/// straight Cartesian line between its ends. The polyline through these points is within a few mm
/// of it.
inline constexpr std::size_t JOINT_PATH_SAMPLES = 16;

/// @brief True if the tool's path of the joint-space move @p from -> @p to (the polyline through
/// JOINT_PATH_SAMPLES + 1 forward-kinematics points of the JACO2) comes nearer than @p clearance_m
/// to a sphere of @p others. What the manager checks every cycle from where the arm is to the
/// phase's goal, and what a planner checks for each move of a job. No allocation.
[[nodiscard]] bool joint_path_blocked(const drivers::jaco::JointAngles& from,
                                      const drivers::jaco::JointAngles& to,
                                      std::span<const Obstacle> others,
                                      double clearance_m) noexcept;

/// @brief How far the tool's path of the joint-space move @p from -> @p to strays from the straight
/// line between its ends (m), over the same samples as joint_path_blocked. A short straight move
/// (approach, lift, place) that strays far is an IK solution on another branch: the wrist would
/// swing round through the scene. No allocation.
[[nodiscard]] double joint_path_deviation(const drivers::jaco::JointAngles& from,
                                          const drivers::jaco::JointAngles& to) noexcept;

/// @brief What to send the arm after a step.
struct ArmRequest {
  enum class Kind : std::uint8_t { NONE, MOVE_JOINTS, MOVE_FINGERS, STOP };
  Kind kind = Kind::NONE;
  drivers::jaco::JointAngles joints{};
  double fingers = 0.0;  ///< all three fingers to this
  double speed_fraction = 1.0;
};

/// @brief The driver's command for @p r (MOVE_JOINTS, MOVE_FINGERS on all three fingers, or STOP
/// for STOP and NONE). No allocation.
[[nodiscard]] drivers::jaco::ArmCommand arm_command(const ArmRequest& r) noexcept;

/// @brief One decision: a phase change and why.
struct Decision {
  std::int64_t stamp_ns = 0;
  Phase from = Phase::IDLE;
  Phase to = Phase::IDLE;
  AbortReason reason = AbortReason::NONE;
  const char* why = "";  ///< static text
};

class ExecutionManager {
 public:
  static constexpr std::size_t LOG_SIZE = 64;  ///< decisions kept (a job takes about 15)
  explicit ExecutionManager(ExecutionLimits limits = {}) noexcept : limits_(limits) {}

  /// @brief Starts @p job at @p now_ns (GO_INITIAL; the next step() returns its move). @return
  /// false if a job is running.
  bool start(const PickPlaceJob& job, std::int64_t now_ns) noexcept;
  /// @brief The next decision. Call every arm cycle with the newest inputs.
  [[nodiscard]] ArmRequest step(std::int64_t now_ns, const ArmInput& arm,
                                const PerceptionInput& perception) noexcept;
  /// @brief The arm refused the request step() returned: the job aborts (REFUSED).
  void refused(std::int64_t now_ns) noexcept;
  /// @brief A person (CLI, the command channel) stops the job: it backs away or holds as for any
  /// abort.
  void request_stop(std::int64_t now_ns) noexcept;

  [[nodiscard]] Phase phase() const noexcept { return phase_; }
  [[nodiscard]] AbortReason abort_reason() const noexcept { return reason_; }
  [[nodiscard]] bool running() const noexcept {
    return phase_ != Phase::IDLE && phase_ != Phase::DONE && phase_ != Phase::ABORTED;
  }
  /// @brief True while the hand holds (or should hold) the object: LIFT to PLACE.
  [[nodiscard]] bool holding() const noexcept;
  /// @brief The decisions so far, oldest first (the last LOG_SIZE).
  [[nodiscard]] std::size_t decisions(std::span<Decision> out) const noexcept;

 private:
  ArmRequest enter(Phase next, std::int64_t now_ns, AbortReason reason, const char* why) noexcept;
  ArmRequest abort(std::int64_t now_ns, AbortReason reason, const char* why) noexcept;
  /// Logs a step within a phase (from = to = the phase).
  void note(std::int64_t now_ns, const char* why) noexcept;
  [[nodiscard]] bool at_joints(const ArmInput& arm,
                               const drivers::jaco::JointAngles& goal) const noexcept;
  [[nodiscard]] bool at_fingers(const ArmInput& arm, double goal) const noexcept;
  [[nodiscard]] const drivers::jaco::JointAngles* joint_goal(Phase phase) const noexcept;
  /// True if every finger closed past the job's touch_fingers.
  [[nodiscard]] bool closed_beyond_open(const ArmInput& arm) const noexcept;
  /// True if the target seen at @p seen has moved from the plan (ExecutionLimits::target_moved_m).
  [[nodiscard]] bool moved(const Eigen::Vector3d& seen) const noexcept;
  [[nodiscard]] bool path_blocked(const ArmInput& arm,
                                  std::span<const Obstacle> others) const noexcept;

  ExecutionLimits limits_;
  PickPlaceJob job_{};
  Phase phase_ = Phase::IDLE;
  AbortReason reason_ = AbortReason::NONE;
  std::int64_t entered_ns_ = 0;
  std::int64_t target_last_seen_ns_ = 0;
  bool risen_reached_ = false;  ///< GO_INITIAL of a job with rise_first: the rise is behind
  bool above_reached_ = false;  ///< PRE_GRASP of a job with via_above: the way-point is behind
  bool aside_reached_ = false;  ///< CARRY of a job with via_aside: the way-point is behind
  bool back_away_after_open_ = false;  ///< an abort while closing: open, then back away
  bool stop_requested_ = false;
  std::int64_t stop_requested_ns_ = 0;
  ArmRequest pending_{};  ///< decided outside step() (start, refused): returned by the next step
  std::array<Decision, LOG_SIZE> log_{};
  std::size_t logged_ = 0;
};

}  // namespace orthoflow::manipulation
