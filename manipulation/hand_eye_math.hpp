#pragma once
/// @file
/// @brief (internal) The numerics both hand-eye solvers use (hand_eye.cpp: target poses;
/// hand_eye_points.cpp: target centres): their limits, the rotation maps, the sample checks and
/// the damped Gauss-Newton refinement. Pure functions; deterministic; they allocate.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <type_traits>

#include <Eigen/Dense>

#include "manipulation/hand_eye.hpp"
#include "manipulation/rigid.hpp"

namespace orthoflow::manipulation {

// The solvers' limits: the samples each needs, the pairs of the pose solver, the rank tests, the
// rigidity tolerance of a sample and the refinement's Jacobian step.
inline constexpr std::size_t MIN_POSE_SAMPLES = 3;
inline constexpr std::size_t MIN_POINT_SAMPLES = 5;
inline constexpr std::size_t ALL_PAIRS_UP_TO = 64;  // beyond: each sample with its next 8
inline constexpr std::size_t NEAR_PAIRS = 8;
// Rank tests. The rotation axes must span at least a plane: the second singular value of the
// axis correlation at least this fraction of the first. The linear systems: their smallest
// singular value at least this fraction of the largest.
inline constexpr double AXIS_SPREAD_MIN = 1e-3;
inline constexpr double LINEAR_CONDITION_MIN = 1e-5;
inline constexpr double HAND_EYE_RIGID_TOLERANCE = 1e-6;
inline constexpr double JACOBIAN_STEP = 1e-7;

/// @brief True if every element of @p t is finite. @pre none.
[[nodiscard]] bool finite(const Eigen::Isometry3d& t) noexcept;
/// @brief The rotation vector (axis times angle) of the rotation @p r. @pre @p r is a rotation.
[[nodiscard]] Eigen::Vector3d log_so3(const Eigen::Matrix3d& r) noexcept;
/// @brief The rotation of the rotation vector @p w (identity for a null vector). @pre none.
[[nodiscard]] Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) noexcept;
/// @brief The nearest rotation to @p m (Frobenius), by SVD. @pre @p m is finite.
[[nodiscard]] Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& m) noexcept;
/// @brief t * exp(delta): rotation perturbed on the right, translation in t's own axes.
/// @pre @p delta points at 6 values (3 rotation, 3 translation).
[[nodiscard]] Eigen::Isometry3d perturbed(const Eigen::Isometry3d& t, const double* delta) noexcept;
/// @brief The smallest singular value of @p m over its largest (0 for a null matrix): the rank
/// test of the linear systems. @pre @p m is finite.
[[nodiscard]] double smallest_over_largest_singular(const Eigen::MatrixXd& m);

/// @brief Gauss-Newton with Levenberg damping and a central-difference Jacobian over a small
/// parameter vector. residual(params, out) fills out (size m) for the parameter offset params.
/// @return the iterations run; @p offset_out: the offset found. @pre @p residual fills @p rows
/// values.
template <class Residual>
int refine(Residual&& residual, Eigen::Index params, Eigen::Index rows, int max_iterations,
           Eigen::VectorXd& offset_out) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(params);
  Eigen::VectorXd r(rows), r_plus(rows), r_minus(rows), r_try(rows);
  Eigen::MatrixXd jacobian(rows, params);
  residual(x, r);
  double cost = r.squaredNorm();
  double lambda = 1e-4;
  int iteration = 0;
  for (; iteration < max_iterations; ++iteration) {
    for (Eigen::Index k = 0; k < params; ++k) {
      Eigen::VectorXd step = x;
      step[k] += JACOBIAN_STEP;
      residual(step, r_plus);
      step[k] = x[k] - JACOBIAN_STEP;
      residual(step, r_minus);
      jacobian.col(k) = (r_plus - r_minus) / (2.0 * JACOBIAN_STEP);
    }
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    const Eigen::VectorXd gradient = jacobian.transpose() * r;
    bool improved = false;
    Eigen::VectorXd delta;
    while (lambda < 1e8) {
      Eigen::MatrixXd damped = normal;
      damped.diagonal() += lambda * normal.diagonal().cwiseMax(1e-12);
      delta = damped.ldlt().solve(-gradient);
      residual(x + delta, r_try);
      const double tried = r_try.squaredNorm();
      if (std::isfinite(tried) && tried <= cost) {
        x += delta;
        r = r_try;
        const double gain = cost - tried;
        cost = tried;
        lambda = std::max(lambda * 0.1, 1e-12);
        improved = gain > 1e-16 * std::max(cost, 1e-30);
        break;
      }
      lambda *= 10.0;
    }
    if (!improved || delta.norm() < 1e-12) {
      ++iteration;
      break;
    }
  }
  offset_out = x;
  return iteration;
}

/// @brief Why @p samples cannot be solved (too few, too many, not finite, not rigid), or nullopt.
/// @pre Sample is PoseSample or PointSample.
template <class Sample>
std::optional<HandEyeError> check_samples(std::span<const Sample> samples, std::size_t minimum) {
  if (samples.size() < minimum) { return HandEyeError::TOO_FEW_SAMPLES; }
  if (samples.size() > HAND_EYE_MAX_SAMPLES) { return HandEyeError::TOO_MANY_SAMPLES; }
  for (const Sample& s : samples) {
    bool ok = finite(s.base_from_gripper);
    if constexpr (std::is_same_v<Sample, PoseSample>) {
      ok = ok && finite(s.camera_from_target);
    } else {
      ok = ok && s.target_in_camera.allFinite();
    }
    if (!ok) { return HandEyeError::NOT_FINITE; }
  }
  for (const Sample& s : samples) {
    bool ok = is_rigid(s.base_from_gripper, HAND_EYE_RIGID_TOLERANCE);
    if constexpr (std::is_same_v<Sample, PoseSample>) {
      ok = ok && is_rigid(s.camera_from_target, HAND_EYE_RIGID_TOLERANCE);
    }
    if (!ok) { return HandEyeError::NOT_RIGID; }
  }
  return std::nullopt;
}

}  // namespace orthoflow::manipulation
