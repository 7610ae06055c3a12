// The stopping envelope (jaco_safety_monitor.hpp): where each joint can be over the next cycle and
// the braking after it, for a host-commanded cycle and for the firmware's own motion.
#include <algorithm>
#include <cmath>

#include "drivers/jaco/jaco_safety_monitor.hpp"

namespace orthoflow::drivers::jaco {
namespace {
constexpr double ENVELOPE_PERIOD_S = static_cast<double>(ARM_PERIOD_NS) * 1e-9;
}  // namespace

JointRange envelope_range(const SafetyLimits& limits, const CycleIntent& in,
                          std::size_t j) noexcept {
  // The model: the measured velocity for the latency; then, for a period, the command (reached at
  // once when it speeds the joint up, reached by braking at brake_decel when it slows or reverses
  // it, a reversal then jumping to the new direction); then braking to rest. The real arm brakes at
  // least as hard and speeds up no faster than at once, so it stays between these extremes; an
  // earlier reaction than the latency assumed adds at most the velocity change times the latency.
  const double latency = static_cast<double>(limits.command_latency_ns) * 1e-9;
  const double d = limits.brake_decel_deg_s2;
  const double v0 = in.velocity[j], vc = in.command[j];
  if (in.firmware) {
    // The firmware drives the joint toward its goal (speeding up to the hardware's speed at most
    // for the latency and a period, then braking) and settles on it within a degree: the braking
    // that would carry it past the goal is cut there. A joint moving away from its goal brakes.
    const double q0 = in.joints[j], goal = in.firmware_goal[j];
    const double dir = goal > q0 ? 1.0 : -1.0;
    const double toward = std::max(0.0, dir * v0);
    const double run = std::max(toward, HARDWARE_SPEED_DEG_S[j]);
    const double far = std::min(run * (latency + ENVELOPE_PERIOD_S) + run * run / (2.0 * d),
                                std::abs(goal - q0) + 1.0);
    const double away = std::max(0.0, -dir * v0);
    const double back = away * (latency + ENVELOPE_PERIOD_S) + away * away / (2.0 * d) + 1.0;
    return {std::min(q0 + dir * far, q0 - dir * back), std::max(q0 + dir * far, q0 - dir * back)};
  }
  double q = in.joints[j] + v0 * latency;
  JointRange range{std::min(in.joints[j], q), std::max(in.joints[j], q)};
  const auto reach = [&](double x) {
    range.lo = std::min(range.lo, x);
    range.hi = std::max(range.hi, x);
  };
  double v = v0;
  double left = ENVELOPE_PERIOD_S;
  if (v * vc < 0.0 || std::abs(vc) < std::abs(v)) {  // slow down toward the command (or to 0)
    const double target = v * vc < 0.0 ? 0.0 : vc;
    const double t = std::min(left, std::abs(v - target) / d);
    q += v * t - std::copysign(0.5 * d * t * t, v);
    v = t < left ? v - std::copysign(d * t, v) : target;
    left -= t;
    reach(q);
  }
  if (left > 0.0 && (v == 0.0 || v * vc > 0.0)) v = vc;  // speeding up: at once
  q += v * left;
  reach(q);
  q += std::copysign(v * v / (2.0 * d), v);  // then braking to rest
  reach(q);
  const double early = std::abs(vc - v0) * latency;
  return {range.lo - early, range.hi + early};
}

}  // namespace orthoflow::drivers::jaco
