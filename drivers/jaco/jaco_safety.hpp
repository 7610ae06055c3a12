#pragma once
/// @file
/// @brief The JACO's host-side safety limits (docs/SAFETY.md, specs/JACO.md 11): a workspace box
/// and keep-out boxes in the base frame, joint limits, speed, acceleration and braking figures,
/// finger range, the body model the whole arm is checked with, and SafetyViolation, which names the
/// limit, the part of the arm and by how much. The checks themselves are the safety monitor's
/// (jaco_safety_monitor.hpp): nothing is clipped, a violation is refused or stops the arm.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "drivers/jaco/jaco_body.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_protocol.hpp"

namespace orthoflow::drivers::jaco {

/// @brief An axis-aligned box in the base frame (metres). As a keep-out it applies to the parts of
/// the arm from `from` on (the base column stands on the table; the base's own box keeps the
/// forearm and everything past it away).
struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  core::FixedText<24> name{};
  BodyPart from = BodyPart::UPPER_ARM;
  /// @brief True if @p p lies inside or on the box. @pre none.
  [[nodiscard]] bool contains(const Eigen::Vector3d& p) const noexcept {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

inline constexpr std::size_t MAX_KEEP_OUT = 8;

/// @brief The JACO2's top joint speeds (Kinova: 36 deg/s for the three large actuators, 48 deg/s
/// for the three small ones): the bound on motion the firmware drives itself (HOME, RETRACT).
inline constexpr std::array<double, 6> HARDWARE_SPEED_DEG_S{36.0, 36.0, 36.0, 48.0, 48.0, 48.0};

/// @brief Every limit the driver enforces. Defaults suit a JACO on a table: a 0.9 m reach box from
/// the base plate up, Kinova's joint limits, conservative caps; no keep-out boxes until a limits
/// file or a caller adds them (docs/SAFETY.md: the table, the camera and the base come from the
/// limits file, manipulation/arm_limits_file.hpp).
struct SafetyLimits {
  /// The whole body stays inside: the arm's reach, 0.9 m around the base, down to 0.1 m below
  /// the base plate. What the arm must not touch there (the table it stands on, the camera, its
  /// own base) are keep-outs (the limits file, manipulation/arm_limits_file.hpp).
  Box workspace{{-0.9, -0.9, -0.1}, {0.9, 0.9, 1.2}, core::FixedText<24>::from("workspace")};
  std::array<Box, MAX_KEEP_OUT> keep_out{};
  std::size_t keep_out_count = 0;
  JointLimits joints = jaco_joint_limits();
  double max_joint_speed_deg_s = 30.0;   ///< host-commanded motion, per joint
  double max_joint_accel_deg_s2 = 40.0;  ///< host-commanded motion, per joint
  /// Deceleration the monitor assumes when it brakes the arm: Kinova publishes none, so a value
  /// at or below any acceleration the host commands (docs/SAFETY.md).
  double brake_decel_deg_s2 = 40.0;
  /// From a packet on the wire to the arm acting on it: the host's period plus the firmware's
  /// latency (an assumption the real arm must confirm: docs/SAFETY.md).
  std::int64_t command_latency_ns = 20'000'000;
  double sweep_resolution_m = 0.005;  ///< the monitor bisects a motion until its bound is this
  double max_finger = 6400.0;         ///< set from the model at open (finger_closed)
  BodyModel body{};                   ///< the whole arm's capsules
  /// The arm's geometry for the checks: set from the detected model at open (static data).
  const ArmGeometry* geometry = &jaco2_geometry();
  /// @brief Adds a keep-out box. @return false if MAX_KEEP_OUT are set already. @pre none.
  bool add_keep_out(const Box& box) noexcept;
  /// @brief The keep-out named @p name, or nullptr. @pre none.
  [[nodiscard]] const Box* find_keep_out(std::string_view name) const noexcept;
};

/// @brief Which limit a command would break, and by how much.
struct SafetyViolation {
  enum class Limit : std::uint8_t {
    NOT_FINITE,    ///< a NaN or infinite value
    JOINT_LIMIT,   ///< joint `joint` past lower/upper (`bound`)
    WORKSPACE,     ///< part `part` would leave the workspace box (near `point`)
    KEEP_OUT,      ///< part `part` would enter keep-out box `box` (near `point`)
    SPEED,         ///< joint `joint` speed above the cap
    ACCELERATION,  ///< joint `joint` acceleration above the cap
    FINGER,        ///< finger `joint` outside [0, max_finger]
    UNREACHABLE,   ///< no joint solution for the pose within the joint limits
    UNPROVEN,      ///< the monitor could not show the motion clear within its work budget
  };
  Limit limit = Limit::NOT_FINITE;
  std::size_t joint = 0;  ///< joint or finger index (0-based), where it applies
  double value = 0.0;     ///< the offending value
  double bound = 0.0;     ///< the limit it broke
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< the part's point nearest the box's wall
  core::FixedText<24> box{};                        ///< the box's name for WORKSPACE/KEEP_OUT
  BodyPart part = BodyPart::HAND;                   ///< for WORKSPACE/KEEP_OUT
  /// WORKSPACE/KEEP_OUT: metres the part (with its margin and the motion's sweep bound) would be
  /// inside the keep-out or outside the workspace; UNPROVEN: the sweep bound left.
  double depth_m = 0.0;
  double ahead_s = 0.0;  ///< how far ahead along the checked motion (s, or path share for moves)
};
/// @brief Lower-case limit name, e.g. "keep_out". @pre none.
[[nodiscard]] const char* to_string(SafetyViolation::Limit limit) noexcept;
/// @brief A sentence naming the limit, e.g. "joint 2 target 320.0 deg is past its upper limit
/// 313.0 deg". @note Allocates (CLI, logs).
[[nodiscard]] std::string describe(const SafetyViolation& violation);

/// @brief Checks finger targets: finite and within [0, max_finger]. @pre none.
[[nodiscard]] Result<void, SafetyViolation> check_fingers(
    const SafetyLimits& limits, const std::array<double, FINGERS>& fingers) noexcept;
/// @brief Checks a Cartesian target cheaply before its IK: finite, the tool point inside the
/// workspace and outside every keep-out (the whole arm is checked along the joint path then).
/// @pre none.
[[nodiscard]] Result<void, SafetyViolation> check_pose(const SafetyLimits& limits,
                                                       const CartesianPose& pose) noexcept;

}  // namespace orthoflow::drivers::jaco
