// The JACO's body as capsules, and the sweep bound (jaco_body.hpp).
#include "drivers/jaco/jaco_body.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace orthoflow::drivers::jaco {
namespace {

constexpr BodyPart ROW_PARTS[6] = {BodyPart::BASE,    BodyPart::UPPER_ARM, BodyPart::FOREARM,
                                   BodyPart::WRIST_1, BodyPart::WRIST_2,   BodyPart::WRIST_3};

BodyCapsule capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                    BodyPart part, std::size_t row) noexcept {
  return BodyCapsule{a, b, radius, part, static_cast<std::uint8_t>(row)};
}

double line_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& axis) noexcept {
  const Eigen::Vector3d d = p - origin;
  return (d - d.dot(axis) * axis).norm();
}

}  // namespace

const char* to_string(BodyPart part) noexcept {
  switch (part) {
    case BodyPart::BASE:
      return "base";
    case BodyPart::UPPER_ARM:
      return "upper_arm";
    case BodyPart::FOREARM:
      return "forearm";
    case BodyPart::WRIST_1:
      return "wrist_1";
    case BodyPart::WRIST_2:
      return "wrist_2";
    case BodyPart::WRIST_3:
      return "wrist_3";
    case BodyPart::HAND:
      return "hand";
    case BodyPart::FINGERTIPS:
      return "fingers";
    case BodyPart::HELD_OBJECT:
      return "held_object";
  }
  return "unknown";
}

std::size_t body_capsules(const JointAngles& joints, const ArmGeometry& geometry,
                          const BodyModel& model, double finger_open, const HeldCapsule& held,
                          BodyCapsules& out) noexcept {
  return body_capsules(forward_kinematics_frames(joints, geometry), geometry, model, finger_open,
                       held, out);
}

std::size_t body_capsules(const ChainFrames& frames, const ArmGeometry& geometry,
                          const BodyModel& model, double finger_open, const HeldCapsule& held,
                          BodyCapsules& out) noexcept {
  std::size_t n = 0;
  for (std::size_t k = 0; k < 6; ++k) {
    const DhRow& row = geometry.rows[k];
    const double radius = model.link_radius_m[k] + model.margin_m;
    const Eigen::Vector3d start = frames[k].translation();
    const Eigen::Vector3d knee = start + row.d_m * frames[k].linear().col(2);
    const Eigen::Vector3d end = frames[k + 1].translation();
    if (std::abs(row.d_m) > 0.0) out[n++] = capsule(start, knee, radius, ROW_PARTS[k], k);
    if (std::abs(row.a_m) > 0.0) out[n++] = capsule(knee, end, radius, ROW_PARTS[k], k);
  }
  const Eigen::Isometry3d& tool = frames[6];
  const Eigen::Vector3d axis = tool.linear().col(2);
  const Eigen::Vector3d at = tool.translation();
  out[n++] = capsule(at - model.hand_back_m * axis, at + model.hand_front_m * axis,
                     model.hand_radius_m + model.margin_m, BodyPart::HAND, 5);
  // The fingers: a bundle around the tool axis that spreads sideways as it opens. Its radius grows
  // with the opening and its front end draws back as much, so the fingertips' reach along the axis
  // stays that of the closed bundle (open fingers spread, they do not grow longer).
  const double spread = std::clamp(finger_open, 0.0, 1.0) * model.finger_open_m;
  out[n++] = capsule(at - model.finger_back_m * axis, at + (model.finger_front_m - spread) * axis,
                     model.finger_radius_m + spread + model.margin_m, BodyPart::FINGERTIPS, 5);
  if (held.held()) {
    out[n++] = capsule(tool * held.a, tool * held.b, held.radius_m + model.margin_m,
                       BodyPart::HELD_OBJECT, 5);
  }
  return n;
}

bool sweep_bounds(const ChainFrames& frames, const BodyCapsules& body, std::size_t count,
                  const std::array<double, 6>& half_turn_deg, std::span<double> bound) noexcept {
  constexpr double RAD = std::numbers::pi / 180.0;
  std::array<double, 6> turn{};
  double total = 0.0;
  for (std::size_t j = 0; j < 6; ++j) total += turn[j] = std::abs(half_turn_deg[j]) * RAD;
  if (total > 0.5) return false;
  // reach[c][j]: the farthest a point of capsule c lies from joint j's axis (distance to a line is
  // convex along a segment, so an end is the farthest, plus the radius).
  std::array<std::array<double, 6>, MAX_BODY_CAPSULES> reach{};
  double pull = 0.0;  // sum_j turn_j * (the farthest any point lies from axis j)
  std::array<double, 6> farthest{};
  for (std::size_t c = 0; c < count; ++c) {
    for (std::size_t j = 0; j <= body[c].row; ++j) {
      const Eigen::Vector3d origin = frames[j].translation();
      const Eigen::Vector3d axis = frames[j].linear().col(2);
      reach[c][j] =
          std::max(line_distance(body[c].a, origin, axis), line_distance(body[c].b, origin, axis)) +
          body[c].radius_m;
      farthest[j] = std::max(farthest[j], reach[c][j]);
    }
  }
  for (std::size_t j = 0; j < 6; ++j) pull += turn[j] * farthest[j];
  const double d_max = pull / (1.0 - total);  // d <= sum turn_j (farthest_j + d)
  for (std::size_t c = 0; c < count; ++c) {
    double b = 0.0;
    for (std::size_t j = 0; j <= body[c].row; ++j) b += turn[j] * (reach[c][j] + d_max);
    bound[c] = b;
  }
  return true;
}

}  // namespace orthoflow::drivers::jaco
