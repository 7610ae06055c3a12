#pragma once
/// @file
/// @brief The JACO's body as capsules (thesis: C_robot; issue 21, item 4): one capsule per segment
/// of the kinematic skeleton (each DH row's d along the previous z, then its a along the new x) and
/// one for the hand around the tool point, each inflated by a margin, placed in the camera frame.
/// kernels::capsule_mask then removes the arm's points from a depth frame before segmentation.
///
/// The radii are conservative planning values for the JACO2 (its links are 7-11 cm across), not
/// vendor figures; the margin also covers the joint-state latency and the calibration error.
/// No allocation; deterministic.
#include <array>
#include <cstddef>
#include <span>

#include <Eigen/Geometry>

#include "drivers/jaco/jaco_kinematics.hpp"
#include "kernels/capsule_mask.hpp"

namespace orthoflow::manipulation {

/// @brief The link model.
struct ArmBodyModel {
  /// Radius of DH row k's segments (row 1: the base column; row 2: the upper arm; ...).
  std::array<double, 6> link_radius_m{0.055, 0.045, 0.045, 0.04, 0.04, 0.04};
  double hand_radius_m = 0.06;  ///< the hand with its fingers open, around the tool axis
  double hand_back_m = 0.10;    ///< the hand's capsule starts this far behind the tool point
  double hand_front_m = 0.04;   ///< and ends this far beyond it (the fingertips)
  double margin_m = 0.02;       ///< every radius inflated by this
};

/// @brief What the hand holds: a capsule whose ends are offsets from the tool point in the base
/// frame (the hand's orientation does not change while it holds: the object stays upright), and its
/// radius. Radius 0: nothing held.
struct HeldObject {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  [[nodiscard]] bool held() const noexcept { return radius_m > 0.0; }
};

/// @brief The held object of a box @p extents (x, y across the table, z up) centred at
/// @p centre, taken by the hand at @p tool (both base frame, at the grasp): its upright axis and
/// the radius of its footprint's circumscribed circle.
[[nodiscard]] HeldObject held_object(const Eigen::Vector3d& tool, const Eigen::Vector3d& centre,
                                     const Eigen::Vector3d& extents,
                                     const Eigen::Vector3d& up) noexcept;

/// @brief Two segments per DH row, the hand, and a held object.
inline constexpr std::size_t ARM_BODY_CAPSULES = 14;

/// @brief The arm's capsules at @p joints in the camera frame (@p base_from_camera from the robot
/// frames file), written to @p out, and @p held's (inflated by the margin) when it holds one.
/// Zero-length segments are left out. @return the count written. @pre finite joints and transform.
[[nodiscard]] std::size_t arm_body_capsules(const drivers::jaco::JointAngles& joints,
                                            const Eigen::Isometry3d& base_from_camera,
                                            const ArmBodyModel& model,
                                            const drivers::jaco::ArmGeometry& geometry,
                                            std::span<kernels::Capsule, ARM_BODY_CAPSULES> out,
                                            const HeldObject& held = {}) noexcept;

/// @brief Sight-line samples of occludes(): every 3 cm or closer over a 1.5 m line.
inline constexpr std::size_t SIGHT_SAMPLES = 50;

/// @brief True if a capsule of @p capsules comes within its radius plus @p target_radius_m of the
/// line of sight from @p eye to @p target (all in one frame; the camera's origin is the eye in the
/// camera frame): the arm stands between the camera and the object, so the object's view is cut and
/// its centre is not evidence of where it is. The line is sampled (SIGHT_SAMPLES points). No
/// allocation. @pre finite inputs.
[[nodiscard]] bool occludes(std::span<const kernels::Capsule> capsules, const Eigen::Vector3d& eye,
                            const Eigen::Vector3d& target, double target_radius_m) noexcept;

}  // namespace orthoflow::manipulation
