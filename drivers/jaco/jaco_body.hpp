#pragma once
/// @file
/// @brief The JACO's whole body as capsules in the base frame, for the safety monitor
/// (jaco_safety_monitor.hpp) and the robot-body filter (manipulation/arm_body.hpp): two capsules
/// per row of the kinematic skeleton (the row's d along the previous z, then its a along the new
/// x), the hand around the tool axis, the fingers (their reach grows with the opening) and a held
/// object, each inflated by the model's margin.
///
/// Also the sweep bound the monitor rests on (sweep_bounds()): while each joint j turns by at most
/// dt_j (radians) either way from a configuration, a point p of the body moves at most
/// sum_j dt_j (dist(p, axis_j) + d_max), where the sum runs over the joints that move p and d_max
/// bounds every point's motion (a point's distance from an axis changes only by its motion relative
/// to the link that carries the axis). Measured at the middle configuration of a stretch of motion,
/// it bounds every capsule's motion over the whole stretch.
///
/// The radii are conservative planning values for the JACO2 (its links are 7-11 cm across, its
/// hand about 10 cm), not vendor figures. The base column (row 1) only turns about its own axis: it
/// never moves in space, so the monitor leaves it out of every check (Box::from). Pure; no
/// allocation; deterministic.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include <Eigen/Geometry>

#include "drivers/jaco/jaco_kinematics.hpp"

namespace orthoflow::drivers::jaco {

/// @brief The body model. The defaults are the monitor's (drivers' SafetyLimits::body): a 1 cm
/// margin, the palm and the fingers apart so that fingertips may come near the table to grasp.
struct BodyModel {
  /// Radius of DH row k's segments (row 1: the base column; row 2: the upper arm; ...).
  std::array<double, 6> link_radius_m{0.055, 0.045, 0.045, 0.04, 0.04, 0.04};
  double hand_radius_m = 0.05;     ///< the palm, around the tool axis
  double hand_back_m = 0.12;       ///< the palm's capsule starts this far behind the tool point
  double hand_front_m = -0.03;     ///< and ends this far beyond it (negative: still behind it)
  double finger_radius_m = 0.015;  ///< the closed fingers' bundle around the tool axis
  double finger_open_m = 0.045;    ///< extra radius of the fingers when fully open
  double finger_back_m = 0.04;     ///< the fingers' capsule starts this far behind the tool point
  double finger_front_m = 0.02;    ///< and ends this far beyond it (the fingertips)
  double margin_m = 0.01;          ///< every radius inflated by this
};

/// @brief A held object as a capsule in the tool frame (it follows the hand's full pose).
/// Radius 0: nothing held.
struct HeldCapsule {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  [[nodiscard]] bool held() const noexcept { return radius_m > 0.0; }
};

/// @brief Which part of the arm a capsule is, for reports ("which link").
enum class BodyPart : std::uint8_t {
  BASE,       ///< row 1: the base column (turns about its own axis only)
  UPPER_ARM,  ///< row 2
  FOREARM,    ///< row 3
  WRIST_1,    ///< row 4
  WRIST_2,    ///< row 5
  WRIST_3,    ///< row 6
  HAND,
  FINGERTIPS,
  HELD_OBJECT,
};
/// @brief Lower-case name, e.g. "forearm". @pre none.
[[nodiscard]] const char* to_string(BodyPart part) noexcept;

/// @brief One capsule of the body, base frame.
struct BodyCapsule {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
  BodyPart part = BodyPart::BASE;
  std::uint8_t row = 0;  ///< joints 1 .. row + 1 move it (the hand and what it holds: all six)
};

/// @brief At most this many capsules: two per row, the hand, the fingers, a held object.
inline constexpr std::size_t MAX_BODY_CAPSULES = 15;
using BodyCapsules = std::array<BodyCapsule, MAX_BODY_CAPSULES>;

/// @brief The body at @p joints with the fingers @p finger_open (0 closed .. 1 open) and @p held,
/// into @p out. Zero-length segments are left out. @return the count. @pre finite joints.
[[nodiscard]] std::size_t body_capsules(const JointAngles& joints, const ArmGeometry& geometry,
                                        const BodyModel& model, double finger_open,
                                        const HeldCapsule& held, BodyCapsules& out) noexcept;
/// @brief The same from the chain's frames at those joints (forward_kinematics_frames).
[[nodiscard]] std::size_t body_capsules(const ChainFrames& frames, const ArmGeometry& geometry,
                                        const BodyModel& model, double finger_open,
                                        const HeldCapsule& held, BodyCapsules& out) noexcept;

/// @brief The sweep bound of every capsule (see the file comment), in metres, into @p bound: the
/// body at @p frames, each joint turning at most @p half_turn_deg either way. @return false when
/// the turns are too large for the bound (their sum past 0.5 rad): split the stretch.
/// @pre bound.size() >= count.
[[nodiscard]] bool sweep_bounds(const ChainFrames& frames, const BodyCapsules& body,
                                std::size_t count, const std::array<double, 6>& half_turn_deg,
                                std::span<double> bound) noexcept;
}  // namespace orthoflow::drivers::jaco
