#pragma once
/// @file
/// @brief Eye-to-hand calibration: where the fixed camera sits in the arm's base frame, from arm
/// poses and the camera's observations of a target the gripper holds (issue 21, item 1).
///
/// Naming: `a_from_b` maps coordinates in frame b to frame a (p_a = a_from_b * p_b). With the
/// gripper's pose A_i = base_from_gripper (forward kinematics or the arm's Cartesian reading) and
/// the observation B_i = camera_from_target, every sample satisfies
///
///     A_i * Y = X * B_i,   X = base_from_camera (the answer), Y = gripper_from_target,
///
/// the AX = YB form of hand-eye calibration. Two observation kinds:
/// - PoseSample: the target's full pose in the camera (a marker, a fitted model). Closed form
///   first: the relative motions A_j^-1 A_i Y = Y B_j^-1 B_i give Y's rotation as the rotation
///   that maps the camera-side rotation axes onto the arm-side ones (Park and Martin 1994, solved
///   by SVD), Y's translation by linear least squares, and X as the rotation mean of A_i Y B_i^-1.
/// - PointSample: only the target's centre in the camera (a ball in the gripper, found in depth).
///   Linear first: A_i p = M c_i + t is linear in p, M (3x3) and t, then M is projected onto a
///   rotation and p, t solved again.
/// Both then refine X and Y by Gauss-Newton with Levenberg damping over every sample's residual
/// (metres in the base frame; radians weighted by HandEyeOptions::rotation_weight_m).
///
/// Pure functions; no state; deterministic. They allocate (not for the frame path).
#include <cstddef>
#include <cstdint>
#include <span>

#include <Eigen/Geometry>

#include "core/result.hpp"

namespace orthoflow::manipulation {

/// @brief One pose of the arm and the target's pose in the camera at that pose.
struct PoseSample {
  Eigen::Isometry3d base_from_gripper = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d camera_from_target = Eigen::Isometry3d::Identity();
};
/// @brief One pose of the arm and the target's centre in the camera (metres).
struct PointSample {
  Eigen::Isometry3d base_from_gripper = Eigen::Isometry3d::Identity();
  Eigen::Vector3d target_in_camera = Eigen::Vector3d::Zero();
};

/// @brief Tuning of the solve.
struct HandEyeOptions {
  /// A radian of rotation error weighs like this many metres of position error: the ratio of
  /// the observations' position noise to their rotation noise. The default pairs about 1.5 mm
  /// with about 0.2 degrees (a marker's pose from an RGB-D camera at 1 m).
  double rotation_weight_m = 0.4;
  int max_iterations = 50;
  /// Relative motions rotating less than this carry no usable axis and are left out of the
  /// closed-form rotation (they still count in the refinement).
  double min_motion_rad = 0.035;  // 2 degrees
};

/// @brief The calibration and how well it explains the samples.
struct HandEyeResult {
  Eigen::Isometry3d base_from_camera = Eigen::Isometry3d::Identity();
  /// For point samples the rotation is the identity and the translation is the target's centre
  /// in the gripper frame.
  Eigen::Isometry3d gripper_from_target = Eigen::Isometry3d::Identity();
  double rms_position_m = 0.0;    ///< |t(A_i Y) - t(X B_i)| (point samples: |A_i p - X c_i|)
  double max_position_m = 0.0;    ///< the worst sample's position residual
  std::size_t worst_sample = 0;   ///< its index: a bad sample shows here (max far above rms)
  double rms_rotation_rad = 0.0;  ///< angle of (A_i Y)^-1 X B_i; 0 for point samples
  std::size_t samples = 0;
  int iterations = 0;  ///< refinement steps taken
};

/// @brief Why no calibration came out.
enum class HandEyeError : std::uint8_t {
  TOO_FEW_SAMPLES,    ///< fewer than 3 pose samples or 5 point samples
  TOO_MANY_SAMPLES,   ///< more than HAND_EYE_MAX_SAMPLES
  NOT_FINITE,         ///< a sample holds NaN or infinity
  NOT_RIGID,          ///< a sample's rotation is not orthonormal with determinant +1
  DEGENERATE_MOTION,  ///< the arm's motions do not determine the answer (e.g. all about one axis)
};
[[nodiscard]] const char* to_string(HandEyeError error) noexcept;

inline constexpr std::size_t HAND_EYE_MAX_SAMPLES = 4096;

/// @brief Solves AX = YB from full target poses. @pre none (bad samples are errors).
[[nodiscard]] Result<HandEyeResult, HandEyeError> solve_hand_eye(
    std::span<const PoseSample> samples, const HandEyeOptions& options = {});
/// @brief Solves A p = X c from target centres. @pre none (bad samples are errors).
[[nodiscard]] Result<HandEyeResult, HandEyeError> solve_hand_eye(
    std::span<const PointSample> samples, const HandEyeOptions& options = {});

/// @brief The rotation angle between two rotations, radians in [0, pi]. @pre rotations.
[[nodiscard]] double rotation_angle_between(const Eigen::Matrix3d& a,
                                            const Eigen::Matrix3d& b) noexcept;

}  // namespace orthoflow::manipulation
