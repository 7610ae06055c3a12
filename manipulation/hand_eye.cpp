// Hand-eye calibration from target poses (manipulation/hand_eye.hpp, PoseSample): the closed form
// of AX = YB (Park and Martin), then the damped refinement; and the error texts. The solver from
// target centres is in hand_eye_points.cpp, the shared numerics in hand_eye_math.hpp.
#include "manipulation/hand_eye.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "manipulation/hand_eye_math.hpp"

namespace orthoflow::manipulation {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix3d = Eigen::Matrix3d;
using Vector3d = Eigen::Vector3d;
using Isometry3d = Eigen::Isometry3d;

}  // namespace

const char* to_string(HandEyeError error) noexcept {
  switch (error) {
    case HandEyeError::TOO_FEW_SAMPLES:
      return "hand-eye: too few samples (at least 3 target poses or 5 target centres)";
    case HandEyeError::TOO_MANY_SAMPLES:
      return "hand-eye: more samples than HAND_EYE_MAX_SAMPLES (4096)";
    case HandEyeError::NOT_FINITE:
      return "hand-eye: a sample holds NaN or infinity";
    case HandEyeError::NOT_RIGID:
      return "hand-eye: a sample's rotation is not a rotation (not orthonormal, or a reflection)";
    case HandEyeError::DEGENERATE_MOTION:
      return "hand-eye: the arm's poses do not determine the camera (rotate the gripper about at "
             "least two different axes, and move it around the workspace)";
  }
  return "hand-eye: unknown error";
}

double rotation_angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) noexcept {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

Result<HandEyeResult, HandEyeError> solve_hand_eye(std::span<const PoseSample> samples,
                                                   const HandEyeOptions& options) {
  if (const auto bad = check_samples(samples, MIN_POSE_SAMPLES)) { return err(*bad); }
  const std::size_t n = samples.size();
  // Relative motions: A_ij Y = Y B_ij with A_ij = A_j^-1 A_i, B_ij = B_j^-1 B_i.
  Matrix3d axis_correlation = Matrix3d::Zero();
  std::vector<std::pair<Isometry3d, Isometry3d>> motions;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t last = n <= ALL_PAIRS_UP_TO ? n : std::min(n, i + 1 + NEAR_PAIRS);
    for (std::size_t j = i + 1; j < last; ++j) {
      const Isometry3d a = samples[j].base_from_gripper.inverse() * samples[i].base_from_gripper;
      const Isometry3d b = samples[j].camera_from_target.inverse() * samples[i].camera_from_target;
      const Vector3d alpha = log_so3(a.linear());
      if (alpha.norm() < options.min_motion_rad) { continue; }
      axis_correlation += alpha * log_so3(b.linear()).transpose();
      motions.emplace_back(a, b);
    }
  }
  if (motions.size() < 2) { return err(HandEyeError::DEGENERATE_MOTION); }
  // Y's rotation maps each beta onto its alpha: Kabsch on the axis correlation (sum alpha beta^T).
  const Eigen::JacobiSVD<Matrix3d> svd(axis_correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  if (svd.singularValues()[1] < AXIS_SPREAD_MIN * svd.singularValues()[0]) {
    return err(HandEyeError::DEGENERATE_MOTION);
  }
  Isometry3d y = Isometry3d::Identity();
  y.linear() = nearest_rotation(axis_correlation);
  // Y's translation: (R_A - I) t_Y = R_Y t_B - t_A over every motion.
  Eigen::MatrixXd lhs(3 * static_cast<Eigen::Index>(motions.size()), 3);
  Eigen::VectorXd rhs(lhs.rows());
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const auto& [a, b] = motions[k];
    const auto row = static_cast<Eigen::Index>(3 * k);
    lhs.block<3, 3>(row, 0) = a.linear() - Matrix3d::Identity();
    rhs.segment<3>(row) = y.linear() * b.translation() - a.translation();
  }
  if (smallest_over_largest_singular(lhs) < LINEAR_CONDITION_MIN) {
    return err(HandEyeError::DEGENERATE_MOTION);
  }
  y.translation() = lhs.colPivHouseholderQr().solve(rhs);
  // X = A_i Y B_i^-1, averaged.
  Matrix3d rotation_sum = Matrix3d::Zero();
  Vector3d translation_sum = Vector3d::Zero();
  for (const PoseSample& s : samples) {
    const Isometry3d xi = s.base_from_gripper * y * s.camera_from_target.inverse();
    rotation_sum += xi.linear();
    translation_sum += xi.translation();
  }
  Isometry3d x = Isometry3d::Identity();
  x.linear() = nearest_rotation(rotation_sum);
  x.translation() = translation_sum / static_cast<double>(n);

  const double w = options.rotation_weight_m;
  const auto rows = static_cast<Eigen::Index>(6 * n);
  auto residual = [&](const Eigen::VectorXd& d, Eigen::VectorXd& out) {
    const Isometry3d xd = perturbed(x, d.data());
    const Isometry3d yd = perturbed(y, d.data() + 6);
    for (std::size_t i = 0; i < n; ++i) {
      const Isometry3d p = samples[i].base_from_gripper * yd;
      const Isometry3d q = xd * samples[i].camera_from_target;
      const auto row = static_cast<Eigen::Index>(6 * i);
      out.segment<3>(row) = p.translation() - q.translation();
      out.segment<3>(row + 3) = w * log_so3(p.linear().transpose() * q.linear());
    }
  };
  Eigen::VectorXd offset;
  HandEyeResult result;
  result.iterations = refine(residual, 12, rows, options.max_iterations, offset);
  result.base_from_camera = perturbed(x, offset.data());
  result.gripper_from_target = perturbed(y, offset.data() + 6);
  double position_sq = 0.0, rotation_sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Isometry3d p = samples[i].base_from_gripper * result.gripper_from_target;
    const Isometry3d q = result.base_from_camera * samples[i].camera_from_target;
    const double dp = (p.translation() - q.translation()).norm();
    const double dr = rotation_angle_between(p.linear(), q.linear());
    position_sq += dp * dp;
    rotation_sq += dr * dr;
    if (dp > result.max_position_m) {
      result.max_position_m = dp;
      result.worst_sample = i;
    }
  }
  result.rms_position_m = std::sqrt(position_sq / static_cast<double>(n));
  result.rms_rotation_rad = std::sqrt(rotation_sq / static_cast<double>(n));
  result.samples = n;
  return result;
}

}  // namespace orthoflow::manipulation
