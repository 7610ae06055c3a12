#pragma once
/// @file
/// @brief Forward and inverse kinematics of the 6-DOF Kinova JACO (curved wrist), from Kinova's
/// published DH parameters (every number and its source: docs/JACO_KINEMATICS_SOURCES.md), with
/// the actuator-to-DH offsets (JACO.md section 8: readings are actuator angles, not DH angles).
/// Angles cross this API as the arm reports them: actuator degrees. Poses are the arm's Cartesian
/// convention: metres in the base frame (JACO.md 8) and Euler angles theta x, y, z in radians with
/// R = Rx(theta_x) * Ry(theta_y) * Rz(theta_z).
///
/// Two published geometries: the JACO2 6-DOF curved wrist (j2n6s300, the default of the functions
/// without an ArmGeometry) and the original JACO ("v1", "R1"), which differs in the wrist lengths,
/// the wrist angle and joint 6's offset (10 degrees). Pick the one of the detected model.
///
/// Pure functions; never allocate; deterministic (the IK's restarts are a fixed sequence).
/// Thread safe: no state.
#include <array>
#include <cstdint>

#include <Eigen/Geometry>

#include "core/result.hpp"

namespace orthoflow::drivers::jaco {

/// @brief Six actuator angles in degrees, joint 1 (base) first.
using JointAngles = std::array<double, 6>;

/// @brief A Cartesian pose as the arm reports it (command 104).
struct CartesianPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< metres, base frame
  Eigen::Vector3d theta = Eigen::Vector3d::Zero();     ///< radians, R = Rx * Ry * Rz
};
/// @brief The transform of @p pose. @pre finite values.
[[nodiscard]] Eigen::Isometry3d to_transform(const CartesianPose& pose) noexcept;
/// @brief The pose of @p transform (theta y in [-pi/2, pi/2]; at gimbal lock, |theta y| = pi/2,
/// theta x is 0 and theta z carries the whole roll). to_transform(to_pose(t)) equals t to rounding
/// everywhere, near gimbal lock too. @pre a rigid transform.
[[nodiscard]] CartesianPose to_pose(const Eigen::Isometry3d& transform) noexcept;

/// @brief One row of a classical (standard) DH table, T = Rz(theta) Tz(d) Tx(a) Rx(alpha), with
/// the map from the actuator angle q: theta = sign * q + offset.
struct DhRow {
  double d_m = 0.0;
  double a_m = 0.0;
  double alpha_rad = 0.0;
  double sign = 1.0;  ///< +1 or -1
  double offset_rad = 0.0;
};
/// @brief An arm's six DH rows, base to end effector (the frame the arm's Cartesian pose names).
struct ArmGeometry {
  std::array<DhRow, 6> rows{};
};
/// @brief JACO2 6-DOF curved wrist (j2n6s300): D4 = D5 = 0.0741 m, D6 = 0.16 m, wrist 60 degrees,
/// theta6 = q6 + 90 degrees. The default geometry. @pre none.
[[nodiscard]] const ArmGeometry& jaco2_geometry() noexcept;
/// @brief The original JACO (v1): D4 = D5 = 0.0743 m, D6 = 0.1687 m, wrist 55 degrees (aa = 11 pi
/// / 72), theta6 = q6 + 100 degrees. @pre none.
[[nodiscard]] const ArmGeometry& jaco_v1_geometry() noexcept;

/// @brief Per-joint limits in actuator degrees; continuous joints carry wide bounds.
struct JointLimits {
  JointAngles lower{};
  JointAngles upper{};
  /// @brief True if every angle lies in [lower, upper]. @pre none.
  [[nodiscard]] bool contains(const JointAngles& angles) const noexcept;
};
/// @brief A joint whose range spans a full turn or more is continuous (its angle may be shifted by
/// 360 degrees). @pre none.
inline constexpr double CONTINUOUS_BOUND_DEG = 10000.0;
/// @brief The 6-DOF JACO's limits, the same on both models: joint 2 in [47, 313], joint 3 in
/// [19, 341], the others continuous (+-CONTINUOUS_BOUND_DEG). @pre none.
[[nodiscard]] JointLimits jaco_joint_limits() noexcept;

/// @brief HOME of the 6-DOF JACO2 in actuator degrees: Kinova's documented Home (j2n6s300.srdf,
/// 275.3, 167.6, 57.4, 240.8, 82.8, 75.8) rounded to half degrees. The simulated arm's HOME and the
/// default IK seed of the planners. @pre none.
inline constexpr JointAngles HOME_JOINTS{275.0, 167.5, 57.5, 240.0, 82.5, 75.0};

/// @brief The end effector's transform in the base frame for @p actuator_deg (JACO2). @pre finite.
[[nodiscard]] Eigen::Isometry3d forward_kinematics(const JointAngles& actuator_deg) noexcept;
/// @brief The same on @p geometry. @pre finite angles.
[[nodiscard]] Eigen::Isometry3d forward_kinematics(const JointAngles& actuator_deg,
                                                   const ArmGeometry& geometry) noexcept;

/// @brief The base frame (identity) and the six DH frames, frame k after row k: frame 6 is the
/// end effector (forward_kinematics). What a link model of the arm is built on.
using ChainFrames = std::array<Eigen::Isometry3d, 7>;
/// @brief The frames of the chain at @p actuator_deg on @p geometry. @pre finite angles.
[[nodiscard]] ChainFrames forward_kinematics_frames(const JointAngles& actuator_deg,
                                                    const ArmGeometry& geometry) noexcept;

/// @brief Why the IK found no solution.
enum class IkError : std::uint8_t {
  NOT_FINITE,   ///< the target or the seed holds NaN or infinity
  UNREACHABLE,  ///< no joint solution within the limits reaches the target within tolerance
};
[[nodiscard]] const char* to_string(IkError error) noexcept;

/// @brief How close an IK solution must come.
struct IkTolerance {
  double position_m = 1e-4;
  double orientation_rad = 1e-3;
};

/// @brief Joint angles reaching @p target within @p tolerance and @p limits, the solution nearest
/// @p seed (the current pose) in joint space among those found from the seed and a fixed set of
/// restarts (JACO2). @pre none (a non-finite target is NOT_FINITE).
/// @note Damped least squares (Levenberg-Marquardt) on the 6D pose error with the analytic
/// Jacobian; a joint pushed past a limit is held at it (active set). At most 13 starts of at most
/// 64 iterations each: about 5 us from a seed within 20 degrees, about 1 ms for a target inside
/// the reach sphere that no start reaches (measured: docs/JACO_KINEMATICS_SOURCES.md). The 12
/// restarts run only when the seed's own solution is missing or lies more than 60 degrees (joint
/// space) from the seed: other solution branches normally lie further, but near the wrist's
/// ill-conditioned poses (q5 near 0 or 180) a solution some degrees nearer may be left unfound.
/// Continuous joints come back shifted by whole turns to lie nearest the seed. Distances are
/// Euclidean over the six angles in degrees. The solution meets the tolerance, no more.
[[nodiscard]] Result<JointAngles, IkError> inverse_kinematics(const Eigen::Isometry3d& target,
                                                              const JointAngles& seed,
                                                              const JointLimits& limits,
                                                              IkTolerance tolerance = {}) noexcept;
/// @brief The same on @p geometry. @pre tolerances positive, lower <= upper on every joint.
[[nodiscard]] Result<JointAngles, IkError> inverse_kinematics(const Eigen::Isometry3d& target,
                                                              const JointAngles& seed,
                                                              const JointLimits& limits,
                                                              IkTolerance tolerance,
                                                              const ArmGeometry& geometry) noexcept;

}  // namespace orthoflow::drivers::jaco
