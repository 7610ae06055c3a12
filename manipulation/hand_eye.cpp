#include "manipulation/hand_eye.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "manipulation/rigid.hpp"

namespace orthoflow::manipulation {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix3d = Eigen::Matrix3d;
using Vector3d = Eigen::Vector3d;
using Isometry3d = Eigen::Isometry3d;

constexpr std::size_t MIN_POSE_SAMPLES = 3;
constexpr std::size_t MIN_POINT_SAMPLES = 5;
constexpr std::size_t ALL_PAIRS_UP_TO = 64;  // beyond: each sample with its next 8
constexpr std::size_t NEAR_PAIRS = 8;
// Rank tests. The rotation axes must span at least a plane: the second singular value of the
// axis correlation at least this fraction of the first. The linear systems: their smallest
// singular value at least this fraction of the largest.
constexpr double AXIS_SPREAD_MIN = 1e-3;
constexpr double LINEAR_CONDITION_MIN = 1e-5;
constexpr double RIGID_TOLERANCE = 1e-6;
constexpr double JACOBIAN_STEP = 1e-7;

bool finite(const Isometry3d& t) noexcept { return t.matrix().allFinite(); }

Vector3d log_so3(const Matrix3d& r) noexcept {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}
Matrix3d exp_so3(const Vector3d& w) noexcept {
  const double angle = w.norm();
  if (angle < 1e-15) { return Matrix3d::Identity(); }
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}
// The nearest rotation to m (Frobenius), by SVD.
Matrix3d nearest_rotation(const Matrix3d& m) noexcept {
  const Eigen::JacobiSVD<Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3d d = Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}
// t * exp(delta): rotation perturbed on the right, translation in t's own axes.
Isometry3d perturbed(const Isometry3d& t, const double* delta) noexcept {
  Isometry3d out = t;
  out.linear() = t.linear() * exp_so3(Vector3d(delta[0], delta[1], delta[2]));
  out.translation() = t.translation() + t.linear() * Vector3d(delta[3], delta[4], delta[5]);
  return out;
}

// Gauss-Newton with Levenberg damping and a central-difference Jacobian over a small parameter
// vector. residual(params, out) fills out (size m) for the parameter offset params.
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
    bool ok = is_rigid(s.base_from_gripper, RIGID_TOLERANCE);
    if constexpr (std::is_same_v<Sample, PoseSample>) {
      ok = ok && is_rigid(s.camera_from_target, RIGID_TOLERANCE);
    }
    if (!ok) { return HandEyeError::NOT_RIGID; }
  }
  return std::nullopt;
}

double smallest_over_largest_singular(const Eigen::MatrixXd& m) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(m);
  const auto& s = svd.singularValues();
  return s[0] > 0.0 ? s[s.size() - 1] / s[0] : 0.0;
}

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
