#pragma once
/// @file
/// @brief The JACO's host-side safety limits and the pure checks every motion command passes before
/// a byte reaches the arm (issue 19, specs/JACO.md 11): a workspace box and keep-out boxes in the
/// base frame, joint limits, joint speed and acceleration caps, finger range. A command that would
/// leave them is refused with a SafetyViolation that names the limit; nothing is clipped.
///
/// What is checked for a joint-space move: the target and the end effector's path, sampled in
/// joint space (the motion planner moves every joint on one synchronised profile, so the path is
/// the straight joint-space segment), must stay inside the workspace and outside every keep-out
/// box. Only the end-effector point is checked, not the links (docs/JACO.md says so).
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_protocol.hpp"

namespace orthoflow::drivers::jaco {

/// @brief An axis-aligned box in the base frame (metres).
struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  core::FixedText<24> name{};
  /// @brief True if @p p lies inside or on the box. @pre none.
  [[nodiscard]] bool contains(const Eigen::Vector3d& p) const noexcept {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

inline constexpr std::size_t MAX_KEEP_OUT = 8;

/// @brief Every limit the driver enforces. Defaults suit a JACO on a table: a 0.9 m reach box above
/// the base plate, no keep-out boxes, Kinova's joint limits, conservative caps.
struct SafetyLimits {
  Box workspace{{-0.9, -0.9, 0.02}, {0.9, 0.9, 1.2}, core::FixedText<24>::from("workspace")};
  std::array<Box, MAX_KEEP_OUT> keep_out{};
  std::size_t keep_out_count = 0;
  JointLimits joints = jaco_joint_limits();
  double max_joint_speed_deg_s = 30.0;   ///< per joint; JACO2 joints reach 36-48 deg/s
  double max_joint_accel_deg_s2 = 60.0;  ///< per joint
  double max_finger = 6400.0;            ///< set from the model at open (finger_closed)
  std::size_t path_samples = 32;         ///< end-effector points checked along a move
  /// The arm's geometry for the path checks: set from the detected model at open (static data).
  const ArmGeometry* geometry = &jaco2_geometry();
  /// @brief Adds a keep-out box. @return false if MAX_KEEP_OUT are set already. @pre none.
  bool add_keep_out(const Box& box) noexcept;
};

/// @brief Which limit a command would break, and by how much.
struct SafetyViolation {
  enum class Limit : std::uint8_t {
    NOT_FINITE,    ///< a NaN or infinite value
    JOINT_LIMIT,   ///< joint `joint` past lower/upper (`bound`)
    WORKSPACE,     ///< the end effector would leave the workspace box (at `point`)
    KEEP_OUT,      ///< the end effector would enter keep-out box `box`
    SPEED,         ///< joint `joint` speed above the cap
    ACCELERATION,  ///< joint `joint` acceleration above the cap
    FINGER,        ///< finger `joint` outside [0, max_finger]
    UNREACHABLE,   ///< no joint solution for the pose within the joint limits
  };
  Limit limit = Limit::NOT_FINITE;
  std::size_t joint = 0;  ///< joint or finger index (0-based), where it applies
  double value = 0.0;     ///< the offending value
  double bound = 0.0;     ///< the limit it broke
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< end-effector point for WORKSPACE/KEEP_OUT
  core::FixedText<24> box{};                        ///< the box's name for WORKSPACE/KEEP_OUT
};
/// @brief Lower-case limit name, e.g. "keep_out". @pre none.
[[nodiscard]] const char* to_string(SafetyViolation::Limit limit) noexcept;
/// @brief A sentence naming the limit, e.g. "joint 2 target 320.0 deg is past its upper limit
/// 313.0 deg". @note Allocates (CLI, logs).
[[nodiscard]] std::string describe(const SafetyViolation& violation);

/// @brief Checks a joint-space move from @p from to @p to: finite, inside the joint limits, and the
/// end effector's sampled path inside the workspace and outside every keep-out box. @pre none.
[[nodiscard]] Result<void, SafetyViolation> check_joint_move(const SafetyLimits& limits,
                                                             const JointAngles& from,
                                                             const JointAngles& to) noexcept;
/// @brief Checks a joint velocity command against the speed cap and, from @p previous over
/// @p dt_s, the acceleration cap. @pre dt_s > 0.
[[nodiscard]] Result<void, SafetyViolation> check_joint_velocity(
    const SafetyLimits& limits, const std::array<double, JOINTS>& velocity,
    const std::array<double, JOINTS>& previous, double dt_s) noexcept;
/// @brief Checks finger targets: finite and within [0, max_finger]. @pre none.
[[nodiscard]] Result<void, SafetyViolation> check_fingers(
    const SafetyLimits& limits, const std::array<double, FINGERS>& fingers) noexcept;
/// @brief Checks a Cartesian target: finite, inside the workspace, outside keep-out boxes. @pre
/// none.
[[nodiscard]] Result<void, SafetyViolation> check_pose(const SafetyLimits& limits,
                                                       const CartesianPose& pose) noexcept;

}  // namespace orthoflow::drivers::jaco
