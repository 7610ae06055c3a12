#pragma once
/// @file
/// @brief The one rigidity check of the manipulation folder: a rotation part that is orthonormal
/// within a tolerance and not a reflection.
#include <Eigen/Geometry>

namespace orthoflow::manipulation {

/// @brief True if @p t's rotation satisfies |R^T R - I| < @p tolerance elementwise and det R > 0.
/// (Finite values are the caller's check.) @pre none.
[[nodiscard]] inline bool is_rigid(const Eigen::Isometry3d& t, double tolerance) noexcept {
  const Eigen::Matrix3d r = t.linear();
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < tolerance &&
         r.determinant() > 0.0;
}

}  // namespace orthoflow::manipulation
