// The safety monitor (jaco_safety_monitor.hpp): the stopping envelope as a box in joint space,
// shown clear by bisection under the body's sweep bound; a straight move, likewise along its path.
#include "drivers/jaco/jaco_safety_monitor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "drivers/jaco/jaco_clearance.hpp"

namespace orthoflow::drivers::jaco {
namespace {

constexpr double RAD = std::numbers::pi / 180.0;
constexpr double PERIOD_S = static_cast<double>(ARM_PERIOD_NS) * 1e-9;
// A firmware cycle's speed is measured over at least five of the arm's 10 ms steps
// (ArmSnapshot::span_velocity; a step more or less than the span's time: a fifth off at most), or
// over two or three where no longer span is known yet (a third): allow that before calling a
// firmware-driven motion too fast.
constexpr double MEASURED_SPEED_SLACK = 1.4;

using Violation = SafetyViolation;

Unexpected<Violation> joint_violation(Violation::Limit limit, std::size_t joint, double value,
                                      double bound, double ahead_s = 0.0) {
  Violation v;
  v.limit = limit;
  v.joint = joint;
  v.value = value;
  v.bound = bound;
  v.ahead_s = ahead_s;
  return err(v);
}

// A stretch of motion to show clear: every joint within [lo, hi] (degrees), or (for a path) the
// points of the straight segment between them. `ahead` is where it lies along the motion.
struct Stretch {
  JointAngles lo{}, hi{};
  double u0 = 0.0, u1 = 1.0;  // a path's share of the move; a box: 0 .. 1 of its envelope
};

// What one stretch needs: the body at its middle, every capsule grown by its sweep bound.
struct NodeResult {
  bool split = false;  // the turns are too large for the bound
  BodyClearance worst{};
  BodyCapsules body{};
};

NodeResult examine(const SafetyLimits& limits, const Stretch& s, double finger_open,
                   const HeldCapsule& held) noexcept {
  NodeResult r;
  JointAngles middle{}, half{};
  for (std::size_t j = 0; j < JOINTS; ++j) {
    middle[j] = 0.5 * (s.lo[j] + s.hi[j]);
    half[j] = 0.5 * (s.hi[j] - s.lo[j]);
  }
  const ChainFrames frames = forward_kinematics_frames(middle, *limits.geometry);
  const std::size_t n =
      body_capsules(frames, *limits.geometry, limits.body, finger_open, held, r.body);
  std::array<double, MAX_BODY_CAPSULES> bound{};
  if (!sweep_bounds(frames, r.body, n, half, bound)) {
    r.split = true;
    return r;
  }
  r.worst = body_clearance(limits, std::span<const BodyCapsule>(r.body.data(), n), bound);
  return r;
}

// The joint whose half-turn moves the body most (by the coarse reach of the chain past it).
std::size_t widest(const Stretch& s) noexcept {
  constexpr std::array<double, 6> WEIGHT{1.0, 0.9, 0.5, 0.3, 0.2, 0.1};  // metres, roughly
  std::size_t best = 0;
  for (std::size_t j = 1; j < JOINTS; ++j)
    if ((s.hi[j] - s.lo[j]) * WEIGHT[j] > (s.hi[best] - s.lo[best]) * WEIGHT[best]) best = j;
  return best;
}

Unexpected<Violation> body_violation(const NodeResult& r, double ahead) {
  Violation v;
  v.limit = r.worst.workspace ? Violation::Limit::WORKSPACE : Violation::Limit::KEEP_OUT;
  v.box = r.worst.box->name;
  v.part = r.body[r.worst.capsule].part;
  v.point = r.worst.point;
  v.depth_m = -r.worst.margin_m;
  v.ahead_s = ahead;
  return err(v);
}

// Shows every stretch clear, halving the ones that are not until their largest half-turn moves the
// body less than the resolution; depth first, so the first violation reported is the earliest.
// A path halves along its segment (both ends move together); a box halves its widest joint.
Result<void, Violation> sweep(const SafetyLimits& limits, const Stretch& whole, bool path,
                              double envelope_s, double finger_open, const HeldCapsule& held,
                              MonitorCost* cost,
                              std::size_t max_nodes = MAX_MONITOR_NODES) noexcept {
  std::array<Stretch, 64> stack{};
  std::size_t top = 0, nodes = 0;
  stack[top++] = whole;
  // Where a stretch lies: a path's share of the move, a box's whole envelope (in seconds).
  const auto ahead = [&](const Stretch& s) { return path ? 0.5 * (s.u0 + s.u1) : envelope_s; };
  while (top > 0) {
    const Stretch s = stack[--top];
    const NodeResult r = examine(limits, s, finger_open, held);
    ++nodes;  // counted whether or not the caller asks for the cost: it bounds the work
    if (cost != nullptr) cost->nodes = nodes;
    if (!r.split && r.worst.margin_m >= 0.0) continue;
    double widest_m = 0.0;
    for (std::size_t j = 0; j < JOINTS; ++j)
      widest_m = std::max(widest_m, std::abs(s.hi[j] - s.lo[j]));
    widest_m *= 0.5 * RAD;  // the largest half-turn in radians, times a metre of reach
    if (!r.split && widest_m <= 0.5 * limits.sweep_resolution_m) return body_violation(r, ahead(s));
    // Every stretch on the stack will be examined: split only while all of them fit the budget.
    if (nodes + top + 2 > max_nodes || top + 2 > stack.size()) {
      Violation v;
      v.limit = Violation::Limit::UNPROVEN;
      v.depth_m = widest_m;
      v.ahead_s = ahead(s);
      return err(v);
    }
    Stretch a = s, b = s;
    if (path) {
      for (std::size_t j = 0; j < JOINTS; ++j) a.hi[j] = b.lo[j] = 0.5 * (s.lo[j] + s.hi[j]);
      a.u1 = b.u0 = 0.5 * (s.u0 + s.u1);
    } else {
      const std::size_t j = widest(s);
      a.hi[j] = b.lo[j] = 0.5 * (s.lo[j] + s.hi[j]);
    }
    stack[top++] = b;
    stack[top++] = a;
  }
  return {};
}

bool finite_held(const HeldCapsule& h) noexcept {
  return h.a.allFinite() && h.b.allFinite() && std::isfinite(h.radius_m);
}
bool same_held(const HeldCapsule& a, const HeldCapsule& b) noexcept {
  return a.a == b.a && a.b == b.b && a.radius_m == b.radius_m;
}

// A firmware cycle within what its proof showed clear: the joints inside the proven box (half a
// degree for a reading's noise), the same held object, the fingers no wider.
bool inside_proof(const FirmwareProof* proof, const CycleIntent& in) noexcept {
  if (proof == nullptr || !proof->valid || !same_held(proof->held, in.held) ||
      in.finger_open > proof->finger_open + 1e-9)
    return false;
  constexpr double SLACK_DEG = 0.5;
  for (std::size_t j = 0; j < JOINTS; ++j)
    if (in.joints[j] < proof->lo[j] - SLACK_DEG || in.joints[j] > proof->hi[j] + SLACK_DEG)
      return false;
  return true;
}

bool finite(const JointVelocity& values) noexcept {
  return std::all_of(values.begin(), values.end(), [](double x) { return std::isfinite(x); });
}

Result<void, Violation> check_rates(const SafetyLimits& limits, const CycleIntent& in) noexcept {
  for (std::size_t j = 0; j < JOINTS; ++j) {
    if (in.firmware) {
      const double speed = std::abs(in.span_measured ? in.span_velocity[j] : in.velocity[j]);
      if (speed > HARDWARE_SPEED_DEG_S[j] * MEASURED_SPEED_SLACK)
        return joint_violation(Violation::Limit::SPEED, j, speed, HARDWARE_SPEED_DEG_S[j]);
      continue;
    }
    const double speed = std::abs(in.command[j]);
    if (speed > limits.max_joint_speed_deg_s * (1.0 + 1e-9))
      return joint_violation(Violation::Limit::SPEED, j, speed, limits.max_joint_speed_deg_s);
    // Slowing down is always allowed (a stop must never be refused); speeding up, or reversing,
    // is held to the cap.
    const bool speeding_up =
        std::abs(in.command[j]) > std::abs(in.previous[j]) || in.command[j] * in.previous[j] < 0.0;
    const double accel = std::abs(in.command[j] - in.previous[j]) / PERIOD_S;
    if (speeding_up && accel > limits.max_joint_accel_deg_s2 * (1.0 + 1e-6))
      return joint_violation(Violation::Limit::ACCELERATION, j, accel,
                             limits.max_joint_accel_deg_s2);
  }
  return {};
}

}  // namespace

Result<void, SafetyViolation> check_cycle(const SafetyLimits& limits, const CycleIntent& intent,
                                          MonitorCost* cost, const FirmwareProof* proof) noexcept {
  CycleIntent in = intent;
  if (in.firmware) in.command = in.velocity;
  if (!finite(in.joints) || !finite(in.velocity) || !finite(in.command) || !finite(in.previous) ||
      !finite(in.span_velocity) || !std::isfinite(in.finger_open) || !finite_held(in.held))
    return joint_violation(Violation::Limit::NOT_FINITE, 0, 0.0, 0.0);
  if (auto rates = check_rates(limits, in); !rates) return rates;
  if (in.firmware && inside_proof(proof, in)) {
    if (cost != nullptr) cost->nodes = 0;
    return {};
  }
  Stretch box;
  double longest = 0.0;
  for (std::size_t j = 0; j < JOINTS; ++j) {
    const JointRange r = envelope_range(limits, in, j);
    if (r.lo < limits.joints.lower[j])
      return joint_violation(Violation::Limit::JOINT_LIMIT, j, r.lo, limits.joints.lower[j]);
    if (r.hi > limits.joints.upper[j])
      return joint_violation(Violation::Limit::JOINT_LIMIT, j, r.hi, limits.joints.upper[j]);
    box.lo[j] = r.lo;
    box.hi[j] = r.hi;
    longest = std::max(longest, std::abs(in.command[j]) / limits.brake_decel_deg_s2);
  }
  const double envelope_s =
      static_cast<double>(limits.command_latency_ns) * 1e-9 + PERIOD_S + longest;
  return sweep(limits, box, false, envelope_s, in.finger_open, in.held, cost);
}

Result<void, SafetyViolation> check_joint_move(const SafetyLimits& limits, const JointAngles& from,
                                               const JointAngles& to, double finger_open,
                                               const HeldCapsule& held,
                                               MonitorCost* cost) noexcept {
  for (std::size_t j = 0; j < JOINTS; ++j) {
    if (!std::isfinite(to[j]) || !std::isfinite(from[j]))
      return joint_violation(Violation::Limit::NOT_FINITE, j, to[j], 0.0);
    if (to[j] < limits.joints.lower[j])
      return joint_violation(Violation::Limit::JOINT_LIMIT, j, to[j], limits.joints.lower[j]);
    if (to[j] > limits.joints.upper[j])
      return joint_violation(Violation::Limit::JOINT_LIMIT, j, to[j], limits.joints.upper[j]);
  }
  if (!std::isfinite(finger_open) || !finite_held(held))
    return joint_violation(Violation::Limit::NOT_FINITE, 0, 0, 0);
  return sweep(limits, Stretch{from, to, 0.0, 1.0}, true, 0.0, finger_open, held, cost);
}

Result<FirmwareProof, SafetyViolation> prove_firmware_motion(
    const SafetyLimits& limits, const JointAngles& from, const JointAngles& goal,
    double finger_open, const HeldCapsule& held, MonitorCost* cost) noexcept {
  if (!std::isfinite(finger_open) || !finite_held(held))
    return joint_violation(Violation::Limit::NOT_FINITE, 0, 0.0, 0.0);
  Stretch box;
  for (std::size_t j = 0; j < JOINTS; ++j) {
    if (!std::isfinite(from[j]) || !std::isfinite(goal[j]))
      return joint_violation(Violation::Limit::NOT_FINITE, j, goal[j], 0.0);
    box.lo[j] = std::min(from[j], goal[j]);
    box.hi[j] = std::max(from[j], goal[j]);
    if (box.lo[j] < limits.joints.lower[j])
      return joint_violation(Violation::Limit::JOINT_LIMIT, j, box.lo[j], limits.joints.lower[j]);
    if (box.hi[j] > limits.joints.upper[j])
      return joint_violation(Violation::Limit::JOINT_LIMIT, j, box.hi[j], limits.joints.upper[j]);
  }
  if (auto clear = sweep(limits, box, false, 0.0, finger_open, held, cost, MAX_FIRMWARE_NODES);
      !clear)
    return err(clear.error());
  FirmwareProof proof;
  proof.valid = true;
  proof.lo = box.lo;
  proof.hi = box.hi;
  proof.finger_open = finger_open;
  proof.held = held;
  return proof;
}

}  // namespace orthoflow::drivers::jaco
