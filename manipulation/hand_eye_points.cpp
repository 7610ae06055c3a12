// Hand-eye calibration from target centres (manipulation/hand_eye.hpp, PointSample): linear least
// squares for the camera's pose and the centre in the gripper, then the damped refinement. The
// solver from full target poses is in hand_eye.cpp, the shared numerics in hand_eye_math.hpp.
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "manipulation/hand_eye.hpp"
#include "manipulation/hand_eye_math.hpp"

namespace orthoflow::manipulation {
namespace {

using Matrix3d = Eigen::Matrix3d;
using Vector3d = Eigen::Vector3d;
using Isometry3d = Eigen::Isometry3d;

}  // namespace

Result<HandEyeResult, HandEyeError> solve_hand_eye(std::span<const PointSample> samples,
                                                   const HandEyeOptions& options) {
  if (const auto bad = check_samples(samples, MIN_POINT_SAMPLES)) { return err(*bad); }
  const std::size_t n = samples.size();
  const auto rows = static_cast<Eigen::Index>(3 * n);
  // A_i p - M c_i - t = -t_Ai, linear in [p; vec(M); t] (vec column-major: M c = sum c_k M.col(k)).
  Eigen::MatrixXd linear(rows, 15);
  Eigen::VectorXd rhs(rows);
  for (std::size_t i = 0; i < n; ++i) {
    const auto row = static_cast<Eigen::Index>(3 * i);
    const Isometry3d& a = samples[i].base_from_gripper;
    const Vector3d& c = samples[i].target_in_camera;
    linear.block<3, 3>(row, 0) = a.linear();
    for (int k = 0; k < 3; ++k) {
      linear.block<3, 3>(row, 3 + 3 * k) = -c[k] * Matrix3d::Identity();
    }
    linear.block<3, 3>(row, 12) = -Matrix3d::Identity();
    rhs.segment<3>(row) = -a.translation();
  }
  if (smallest_over_largest_singular(linear) < LINEAR_CONDITION_MIN) {
    return err(HandEyeError::DEGENERATE_MOTION);
  }
  const Eigen::VectorXd z = linear.colPivHouseholderQr().solve(rhs);
  Isometry3d x = Isometry3d::Identity();
  x.linear() = nearest_rotation(Eigen::Map<const Matrix3d>(z.data() + 3));
  // With the rotation fixed: A_i p - t = R c_i - t_Ai.
  Eigen::MatrixXd lhs(rows, 6);
  for (std::size_t i = 0; i < n; ++i) {
    const auto row = static_cast<Eigen::Index>(3 * i);
    const Isometry3d& a = samples[i].base_from_gripper;
    lhs.block<3, 3>(row, 0) = a.linear();
    lhs.block<3, 3>(row, 3) = -Matrix3d::Identity();
    rhs.segment<3>(row) = x.linear() * samples[i].target_in_camera - a.translation();
  }
  const Eigen::VectorXd pt = lhs.colPivHouseholderQr().solve(rhs);
  Vector3d p = pt.head<3>();
  x.translation() = pt.tail<3>();

  auto residual = [&](const Eigen::VectorXd& d, Eigen::VectorXd& out) {
    const Isometry3d xd = perturbed(x, d.data());
    const Vector3d pd = p + d.segment<3>(6);
    for (std::size_t i = 0; i < n; ++i) {
      out.segment<3>(static_cast<Eigen::Index>(3 * i)) =
          samples[i].base_from_gripper * pd - xd * samples[i].target_in_camera;
    }
  };
  Eigen::VectorXd offset;
  HandEyeResult result;
  result.iterations = refine(residual, 9, rows, options.max_iterations, offset);
  result.base_from_camera = perturbed(x, offset.data());
  p += offset.segment<3>(6);
  result.gripper_from_target = Isometry3d::Identity();
  result.gripper_from_target.translation() = p;
  double position_sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dp =
        (samples[i].base_from_gripper * p - result.base_from_camera * samples[i].target_in_camera)
            .norm();
    position_sq += dp * dp;
    if (dp > result.max_position_m) {
      result.max_position_m = dp;
      result.worst_sample = i;
    }
  }
  result.rms_position_m = std::sqrt(position_sq / static_cast<double>(n));
  result.samples = n;
  return result;
}

}  // namespace orthoflow::manipulation
