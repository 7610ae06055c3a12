#include "drivers/jaco/jaco_safety.hpp"

#include <cmath>
#include <cstdio>

namespace orthoflow::drivers::jaco {
namespace {

using Violation = SafetyViolation;

Unexpected<Violation> violation(Violation::Limit limit, std::size_t joint, double value,
                                double bound) {
  Violation v;
  v.limit = limit;
  v.joint = joint;
  v.value = value;
  v.bound = bound;
  return err(v);
}

Result<void, Violation> check_point(const SafetyLimits& limits, const Eigen::Vector3d& p) {
  const auto box_violation = [&](Violation::Limit limit, const Box& box) {
    Violation v;
    v.limit = limit;
    v.point = p;
    v.box = box.name;
    return err(v);
  };
  if (!limits.workspace.contains(p))
    return box_violation(Violation::Limit::WORKSPACE, limits.workspace);
  for (std::size_t i = 0; i < limits.keep_out_count; ++i) {
    if (limits.keep_out[i].contains(p)) {
      return box_violation(Violation::Limit::KEEP_OUT, limits.keep_out[i]);
    }
  }
  return {};
}

}  // namespace

bool SafetyLimits::add_keep_out(const Box& box) noexcept {
  if (keep_out_count == MAX_KEEP_OUT) return false;
  keep_out[keep_out_count++] = box;
  return true;
}

const Box* SafetyLimits::find_keep_out(std::string_view name) const noexcept {
  for (std::size_t i = 0; i < keep_out_count; ++i)
    if (keep_out[i].name.view() == name) return &keep_out[i];
  return nullptr;
}

const char* to_string(SafetyViolation::Limit limit) noexcept {
  switch (limit) {
    case Violation::Limit::NOT_FINITE:
      return "not_finite";
    case Violation::Limit::JOINT_LIMIT:
      return "joint_limit";
    case Violation::Limit::WORKSPACE:
      return "workspace";
    case Violation::Limit::KEEP_OUT:
      return "keep_out";
    case Violation::Limit::SPEED:
      return "speed";
    case Violation::Limit::ACCELERATION:
      return "acceleration";
    case Violation::Limit::FINGER:
      return "finger";
    case Violation::Limit::UNREACHABLE:
      return "unreachable";
    case Violation::Limit::UNPROVEN:
      return "unproven";
  }
  return "unknown";
}

std::string describe(const SafetyViolation& v) {
  char text[200];
  const auto joint = static_cast<unsigned>(v.joint + 1);
  switch (v.limit) {
    case Violation::Limit::NOT_FINITE:
      std::snprintf(text, sizeof text, "a target value is NaN or infinite");
      break;
    case Violation::Limit::JOINT_LIMIT:
      std::snprintf(text, sizeof text, "joint %u target %.2f deg is past its %s limit %.2f deg",
                    joint, v.value, v.value > v.bound ? "upper" : "lower", v.bound);
      break;
    case Violation::Limit::WORKSPACE:
      std::snprintf(
          text, sizeof text,
          "the %s would leave the %s box by %.1f mm near (%.3f, %.3f, %.3f) m, %.2f s ahead",
          to_string(v.part), std::string(v.box.view()).c_str(), 1000.0 * v.depth_m, v.point.x(),
          v.point.y(), v.point.z(), v.ahead_s);
      break;
    case Violation::Limit::KEEP_OUT:
      std::snprintf(text, sizeof text,
                    "the %s would enter keep-out box '%s' by %.1f mm near (%.3f, %.3f, %.3f) m, "
                    "%.2f s ahead",
                    to_string(v.part), std::string(v.box.view()).c_str(), 1000.0 * v.depth_m,
                    v.point.x(), v.point.y(), v.point.z(), v.ahead_s);
      break;
    case Violation::Limit::SPEED:
      std::snprintf(text, sizeof text, "joint %u speed %.2f deg/s exceeds the cap %.2f deg/s",
                    joint, v.value, v.bound);
      break;
    case Violation::Limit::ACCELERATION:
      std::snprintf(text, sizeof text,
                    "joint %u acceleration %.2f deg/s^2 exceeds the cap %.2f deg/s^2", joint,
                    v.value, v.bound);
      break;
    case Violation::Limit::FINGER:
      std::snprintf(text, sizeof text, "finger %u target %.2f is outside [0, %.2f]", joint, v.value,
                    v.bound);
      break;
    case Violation::Limit::UNREACHABLE:
      std::snprintf(text, sizeof text,
                    "no joint solution reaches the pose within the joint limits");
      break;
    case Violation::Limit::UNPROVEN:
      std::snprintf(text, sizeof text,
                    "the motion could not be shown clear of the limits within the check's budget "
                    "(%.1f mm of sweep left), so it is not made",
                    1000.0 * v.depth_m);
      break;
  }
  return std::string("safety: ") + to_string(v.limit) + ": " + text;
}

Result<void, SafetyViolation> check_fingers(const SafetyLimits& limits,
                                            const std::array<double, FINGERS>& fingers) noexcept {
  for (std::size_t f = 0; f < FINGERS; ++f) {
    if (!std::isfinite(fingers[f])) return violation(Violation::Limit::NOT_FINITE, f, 0.0, 0.0);
    if (fingers[f] < 0.0 || fingers[f] > limits.max_finger) {
      return violation(Violation::Limit::FINGER, f, fingers[f], limits.max_finger);
    }
  }
  return {};
}

Result<void, SafetyViolation> check_pose(const SafetyLimits& limits,
                                         const CartesianPose& pose) noexcept {
  if (!pose.position.allFinite() || !pose.theta.allFinite()) {
    return violation(Violation::Limit::NOT_FINITE, 0, 0.0, 0.0);
  }
  return check_point(limits, pose.position);
}

}  // namespace orthoflow::drivers::jaco
