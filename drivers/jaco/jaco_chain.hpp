#pragma once
/// @file
/// @brief The DH chain of the JACO (jaco_kinematics.hpp), shared by the forward kinematics
/// (jaco_kinematics.cpp) and the inverse kinematics (jaco_inverse_kinematics.cpp): one row's
/// transform, and the tip with every joint's axis and origin in the base frame. Internal to
/// drivers/jaco. Header only; pure, never allocates.
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>

#include <Eigen/Geometry>

#include "drivers/jaco/jaco_kinematics.hpp"

namespace orthoflow::drivers::jaco::detail {

using Vector6d = Eigen::Matrix<double, 6, 1>;

inline constexpr double PI = std::numbers::pi;
inline constexpr double DEG = PI / 180.0;

inline Vector6d vec(const JointAngles& a) noexcept { return Eigen::Map<const Vector6d>(a.data()); }

inline Eigen::Isometry3d dh_transform(const DhRow& row, double q_rad) noexcept {
  const double theta = row.sign * q_rad + row.offset_rad;
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(row.alpha_rad), sa = std::sin(row.alpha_rad);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() << ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca;
  t.translation() << row.a_m * ct, row.a_m * st, row.d_m;
  return t;
}

// The tip and, per joint, its axis and a point on it in the base frame (z axis and origin of the
// frame before the joint's row): forward kinematics and what the geometric Jacobian needs.
struct Chain {
  Eigen::Isometry3d tip = Eigen::Isometry3d::Identity();
  std::array<Eigen::Vector3d, 6> axis{}, origin{};
};

inline Chain chain(const ArmGeometry& g, const Vector6d& q_rad) noexcept {
  Chain c;
  for (std::size_t i = 0; i < 6; ++i) {
    c.axis[i] = c.tip.linear().col(2);
    c.origin[i] = c.tip.translation();
    c.tip = c.tip * dh_transform(g.rows[i], q_rad(static_cast<Eigen::Index>(i)));
  }
  return c;
}

}  // namespace orthoflow::drivers::jaco::detail
