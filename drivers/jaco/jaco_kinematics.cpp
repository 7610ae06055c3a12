// Forward kinematics of the JACO (jaco_kinematics.hpp): the two published DH tables, the Euler
// convention of the arm's Cartesian pose, the joint limits, and the tip and frames of the chain.
// The inverse kinematics is in jaco_inverse_kinematics.cpp.
#include "drivers/jaco/jaco_kinematics.hpp"

#include <algorithm>
#include <cmath>

#include "drivers/jaco/jaco_chain.hpp"

namespace orthoflow::drivers::jaco {
namespace {

using detail::chain;
using detail::DEG;
using detail::dh_transform;
using detail::PI;
using detail::vec;

// Kinova's classical table of the 6-DOF curved-wrist arm (docs/JACO_KINEMATICS_SOURCES.md): the
// three wrist rows carry the lengths projected onto the 2aa-inclined wrist axes, sa / s2a.
ArmGeometry curved_wrist(double d4, double d5, double d6, double aa, double offset6) noexcept {
  constexpr double D1 = 0.2755, D2 = 0.4100, D3 = 0.2073, E2 = 0.0098;
  const double k = std::sin(aa) / std::sin(2.0 * aa);
  return {{{{D1, 0.0, PI / 2, -1.0, 0.0},  // {d, a, alpha, sign, offset}
            {0.0, D2, PI, 1.0, -PI / 2},
            {-E2, 0.0, PI / 2, 1.0, PI / 2},
            {-(D3 + k * d4), 0.0, 2.0 * aa, 1.0, 0.0},
            {-(k * d4 + k * d5), 0.0, 2.0 * aa, 1.0, -PI},
            {-(k * d5 + d6), 0.0, PI, 1.0, offset6}}}};
}

}  // namespace

Eigen::Isometry3d to_transform(const CartesianPose& pose) noexcept {
  Eigen::Isometry3d t(Eigen::AngleAxisd(pose.theta.x(), Eigen::Vector3d::UnitX()) *
                      Eigen::AngleAxisd(pose.theta.y(), Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(pose.theta.z(), Eigen::Vector3d::UnitZ()));
  t.translation() = pose.position;
  return t;
}

// R = Rx Ry Rz: theta x from column 2 (sy, -sx cy, cx cy), then y and z from Rx(-tx) R = Ry Rz, so
// that theta z absorbs any error of theta x: exact round trips near gimbal lock too.
CartesianPose to_pose(const Eigen::Isometry3d& transform) noexcept {
  const Eigen::Matrix3d& r = transform.linear();
  const double cy_sx = -r(1, 2), cy_cx = r(2, 2);
  const double tx = std::hypot(cy_sx, cy_cx) < 1e-15 ? 0.0 : std::atan2(cy_sx, cy_cx);
  const double cx = std::cos(tx), sx = std::sin(tx);
  const double sz = cx * r(1, 0) + sx * r(2, 0), cz = cx * r(1, 1) + sx * r(2, 1);
  const double cy = std::max(0.0, -sx * r(1, 2) + cx * r(2, 2));  // >= 0 but for rounding
  return {transform.translation(), {tx, std::atan2(r(0, 2), cy), std::atan2(sz, cz)}};
}

const ArmGeometry& jaco2_geometry() noexcept {
  static const ArmGeometry g = curved_wrist(0.0741, 0.0741, 0.1600, PI / 6, PI / 2);
  return g;
}

const ArmGeometry& jaco_v1_geometry() noexcept {
  static const ArmGeometry g = curved_wrist(0.0743, 0.0743, 0.1687, 11 * PI / 72, 100 * DEG);
  return g;
}

bool JointLimits::contains(const JointAngles& angles) const noexcept {
  const Eigen::Array<double, 6, 1> q = vec(angles);  // compared so that NaN is outside
  return ((q >= vec(lower).array()) && (q <= vec(upper).array())).all();
}

JointLimits jaco_joint_limits() noexcept {
  constexpr double C = CONTINUOUS_BOUND_DEG;
  return {{-C, 47.0, 19.0, -C, -C, -C}, {C, 313.0, 341.0, C, C, C}};
}

Eigen::Isometry3d forward_kinematics(const JointAngles& actuator_deg) noexcept {
  return forward_kinematics(actuator_deg, jaco2_geometry());
}

Eigen::Isometry3d forward_kinematics(const JointAngles& actuator_deg,
                                     const ArmGeometry& geometry) noexcept {
  return chain(geometry, vec(actuator_deg) * DEG).tip;
}

ChainFrames forward_kinematics_frames(const JointAngles& actuator_deg,
                                      const ArmGeometry& geometry) noexcept {
  ChainFrames frames;
  frames[0] = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < 6; ++i) {
    frames[i + 1] = frames[i] * dh_transform(geometry.rows[i], actuator_deg[i] * DEG);
  }
  return frames;
}

}  // namespace orthoflow::drivers::jaco
