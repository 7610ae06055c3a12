// The non-template numerics of the hand-eye solvers (manipulation/hand_eye_math.hpp): the
// rotation maps, the perturbation the refinement moves along, and the rank test.
#include "manipulation/hand_eye_math.hpp"

#include <Eigen/Dense>

namespace orthoflow::manipulation {
namespace {

using Matrix3d = Eigen::Matrix3d;
using Vector3d = Eigen::Vector3d;
using Isometry3d = Eigen::Isometry3d;

}  // namespace

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

double smallest_over_largest_singular(const Eigen::MatrixXd& m) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(m);
  const auto& s = svd.singularValues();
  return s[0] > 0.0 ? s[s.size() - 1] / s[0] : 0.0;
}

}  // namespace orthoflow::manipulation
