// The safety monitor's property test generator (arm_sequence.hpp).
#include "tests/drivers/jaco/arm_sequence.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "drivers/jaco/jaco_kinematics.hpp"
#include "tests/drivers/jaco/arm_truth.hpp"
#include "tests/drivers/jaco/jaco_test_rig.hpp"

namespace orthoflow::test {
namespace {

using jaco::ArmCommand;
using Kind = ArmCommand::Kind;

constexpr std::int64_t MS = 1'000'000;

// A simulated dynamics every sequence shares (the defaults: what the bound is stated for).
const simulation::SimJacoDynamics DYNAMICS{};

std::string where(int cycle) { return "cycle " + std::to_string(cycle) + ": "; }

double speed_of(const simulation::SimJacoArm& arm) {
  double v = 0.0;
  for (double x : arm.joint_velocities()) v = std::max(v, std::abs(x));
  return v;
}

// Random keep-outs that leave the arm's start clear (with the monitor's margin): a table some way
// under the hand, and up to three boxes near poses the arm can reach.
void add_keep_outs(Chooser& c, const jaco::JointAngles& start, jaco::SafetyLimits& limits) {
  const auto clear_at_start = [&](const jaco::Box& b) {
    jaco::SafetyLimits probe = limits;
    probe.keep_out_count = 0;
    if (!probe.add_keep_out(b)) return false;
    jaco::BodyCapsules body{};
    const std::size_t n = jaco::body_capsules(start, *probe.geometry, probe.body, 1.0, {}, body);
    std::array<double, jaco::MAX_BODY_CAPSULES> none{};
    return jaco::body_clearance(probe, std::span(body.data(), n), none).margin_m > 0.0;
  };
  const double hand_z = jaco::forward_kinematics(start).translation().z();
  jaco::Box table{{-0.9, -0.9, -0.2},
                  {0.9, 0.9, hand_z - c.uniform(0.08, 0.45)},
                  core::FixedText<24>::from("table")};
  if (clear_at_start(table)) (void)limits.add_keep_out(table);
  const std::uint32_t boxes = c.below(4);
  for (std::uint32_t i = 0; i < boxes; ++i) {
    jaco::JointAngles q = start;
    for (double& a : q) a += c.uniform(-70.0, 70.0);
    const Eigen::Vector3d centre = jaco::forward_kinematics(q).translation();
    const Eigen::Vector3d half(c.uniform(0.002, 0.12), c.uniform(0.002, 0.12),
                               c.uniform(0.002, 0.12));
    jaco::Box b{centre - half, centre + half, core::FixedText<24>::from("box")};
    b.name.assign("box" + std::to_string(i));
    const jaco::BodyPart parts[] = {jaco::BodyPart::UPPER_ARM, jaco::BodyPart::FOREARM,
                                    jaco::BodyPart::HAND};
    b.from = parts[c.below(3)];
    if (clear_at_start(b)) (void)limits.add_keep_out(b);
  }
}

// The client's velocity stream under way: toward target, ramped at a random share of the cap (or
// jumped: the monitor refuses the jump).
struct Stream {
  jaco::JointVelocity target{};
  jaco::JointVelocity now{};
  double ramp = 0.0;  ///< deg/s per cycle; 0: jump
  int left = 0;
};

ArmCommand random_command(Chooser& c, const jaco::ArmSnapshot& s, double max_finger,
                          Stream& stream) {
  ArmCommand cmd;
  switch (c.below(8)) {
    case 0:
    case 1: {
      cmd.kind = Kind::MOVE_JOINTS;
      cmd.joints = s.joints;
      const std::uint32_t moved = 1 + c.below(6);
      for (std::uint32_t k = 0; k < moved; ++k) cmd.joints[c.below(6)] += c.uniform(-110.0, 110.0);
      cmd.speed_fraction = c.chance(0.1) ? c.uniform(1.0, 1.5) : c.uniform(0.05, 1.0);
      return cmd;
    }
    case 2:
      cmd.kind = Kind::MOVE_POSE;
      cmd.pose.position = {c.uniform(-0.8, 0.8), c.uniform(-0.8, 0.8), c.uniform(-0.2, 1.0)};
      cmd.pose.theta = s.pose.theta + Eigen::Vector3d(c.uniform(-0.5, 0.5), c.uniform(-0.5, 0.5),
                                                      c.uniform(-0.5, 0.5));
      cmd.speed_fraction = c.uniform(0.05, 1.0);
      return cmd;
    case 3:
    case 4: {
      stream = {};
      for (double& v : stream.target) v = c.chance(0.5) ? c.uniform(-35.0, 35.0) : 0.0;
      stream.ramp = c.chance(0.15) ? 0.0 : c.uniform(0.1, 0.45);  // the cap: 0.4 deg/s a cycle
      stream.left = 10 + static_cast<int>(c.below(120));
      cmd.kind = Kind::KEEP_ALIVE;
      return cmd;
    }
    case 5:
      cmd.kind = Kind::MOVE_FINGERS;
      for (double& f : cmd.fingers) f = c.uniform(-0.05 * max_finger, 1.05 * max_finger);
      return cmd;
    case 6:
      cmd.kind = c.chance(0.5) ? Kind::HOME : Kind::RETRACT;
      return cmd;
    default:
      cmd.kind = Kind::STOP;
      return cmd;
  }
}

jaco::HeldCapsule random_held(Chooser& c) {
  if (c.chance(0.4)) return {};
  const double length = c.uniform(0.02, 0.3);
  return {{0.0, 0.0, c.uniform(-0.02, 0.05)}, {0.0, 0.0, length}, c.uniform(0.01, 0.05)};
}

}  // namespace

std::uint32_t SeededChooser::below(std::uint32_t n) {
  state_ += 0x9E3779B97F4A7C15ULL;
  std::uint64_t z = state_;
  z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
  z ^= z >> 31U;
  return static_cast<std::uint32_t>(z % n);
}

std::uint32_t ByteChooser::below(std::uint32_t n) {
  std::uint32_t v = 0;
  for (int i = 0; i < 3; ++i) v = (v << 8U) | (at_ < bytes_.size() ? bytes_[at_++] : 0U);
  return v % n;
}

std::int64_t stop_bound_ns(double speed_deg_s) {
  // Until the stop acts the arm follows what it was told, speeding up at most at its acceleration.
  const std::int64_t until_acting = jaco::ARM_PERIOD_NS + DYNAMICS.command_latency_ns;
  const double fastest = speed_deg_s + DYNAMICS.accel_deg_s2 * 1e-9 * double(until_acting);
  return until_acting + static_cast<std::int64_t>(fastest / DYNAMICS.decel_deg_s2 * 1e9) +
         3 * jaco::ARM_PERIOD_NS;
}

SequenceResult run_arm_sequence(Chooser& c, int cycles, std::ostream* trace) {
  SequenceResult r;
  simulation::SimJacoConfig config = JacoRig::home_config();
  config.dynamics = DYNAMICS;
  config.fault_seed = c.below(1U << 30);
  std::optional<std::pair<std::int64_t, std::int64_t>> silent;
  if (c.chance(0.2)) {
    const std::int64_t from = static_cast<std::int64_t>(100 + c.below(1200)) * MS;
    silent = {from, from + static_cast<std::int64_t>(5 + c.below(200)) * MS};
    config.faults.silent_from_ns = silent->first;
    config.faults.silent_until_ns = silent->second;
  }
  if (c.chance(0.2)) config.faults.garbage_reply_rate = 0.02;
  if (c.chance(0.2)) config.faults.corrupt_body_rate = 0.02;
  jaco::ControllerOptions options;
  {
    simulation::SimJacoConfig calm = config;
    calm.faults = {};
    JacoRig probe(calm);
    add_keep_outs(c, probe.arm().joints(), options.limits);
  }
  // Opening may fail on a garbage reply (the driver says so, as to a user): open again, as one
  // would, with the fault draws moved on.
  std::unique_ptr<JacoRig> opened;
  for (int attempt = 0; attempt < 8 && !opened; ++attempt) {
    try {
      opened = std::make_unique<JacoRig>(config, options);
    } catch (const std::runtime_error&) { config.fault_seed += 7919; }
  }
  if (!opened) {  // the driver refused a link that garbled its start-up every time: nothing moved
    r.unopened = true;
    return r;
  }
  JacoRig& rig = *opened;
  const jaco::SafetyLimits& limits = rig.controller->options().limits;
  const double feed_rate = c.uniform(0.3, 1.0);
  Stream stream;
  jaco::HeldCapsule held;
  // A stop is judged while the link works: with the link faulted (a silent or garbling arm) the
  // host cannot reach the arm, which finishes what it was last told (docs/SAFETY.md).
  struct PendingStop {
    bool active = false;
    std::int64_t at = 0;
    std::int64_t bound = 0;
    bool link_lost = false;
  } stop;
  std::int64_t reset_at = -1;
  for (int i = 0; i < cycles && r.ok; ++i) {
    const jaco::ArmSnapshot s = rig.controller->snapshot();
    if (c.chance(0.08)) {
      const std::uint32_t what = c.below(10);
      if (what < 7) {
        const ArmCommand cmd = random_command(c, s, limits.max_finger, stream);
        const bool refused = cmd.kind != Kind::KEEP_ALIVE && !rig.controller->submit(cmd);
        if (refused) ++r.refused;
        // A new motion accepted ends the stop's measure: the arm was asked to move again.
        if (!refused && cmd.kind != Kind::STOP && cmd.kind != Kind::KEEP_ALIVE &&
            cmd.kind != Kind::MOVE_FINGERS)
          stop.active = false;
        if (trace != nullptr) {
          *trace << "cycle " << i << " command " << static_cast<int>(cmd.kind)
                 << (refused ? " refused" : " accepted") << " joints";
          for (double q : cmd.joints) *trace << ' ' << q;
          *trace << " pose " << cmd.pose.position.transpose() << '\n';
        }
        if (cmd.kind == Kind::STOP) {
          ++r.stops;
          stream.left = 0;
          if (!stop.active)
            stop = PendingStop{true, rig.now(), stop_bound_ns(speed_of(rig.arm())), s.fault};
        }
      } else if (what < 9) {
        // A grasp: the object is where the hand is. One that would already be inside a keep-out is
        // not one the hand could have picked up (the monitor would refuse every motion then).
        const jaco::HeldCapsule next = random_held(c);
        if (true_clearance(limits, rig.arm(), next).margin_m > 0.0) {
          held = next;
          rig.controller->set_held(held);
        }
      } else {
        rig.controller->estop();
        ++r.stops;
        stream.left = 0;
        if (!stop.active)
          stop = PendingStop{true, rig.now(), stop_bound_ns(speed_of(rig.arm())), s.fault};
        reset_at = rig.now() + static_cast<std::int64_t>(50 + c.below(400)) * MS;
      }
    }
    if (stream.left > 0) {
      --stream.left;
      for (std::size_t j = 0; j < jaco::JOINTS; ++j) {
        const double step = stream.ramp > 0.0 ? stream.ramp : 1e9;
        stream.now[j] += std::clamp(stream.target[j] - stream.now[j], -step, step);
      }
      ArmCommand v;
      v.kind = Kind::VELOCITY;
      v.velocity = stream.now;
      if (!rig.controller->submit(v)) {
        ++r.refused;
        stream.left = 0;
        stream.now = {};
      } else {
        stop.active = false;  // moving again, as asked
      }
    }
    if (reset_at >= 0 && rig.now() >= reset_at && !rig.arm().moving()) {
      (void)rig.controller->reset_estop();
      reset_at = -1;
    }
    rig.cycle(c.chance(feed_rate));
    rig.controller->guard(rig.now());
    ++r.cycles;
    const jaco::BodyClearance truth = true_clearance(limits, rig.arm(), held);
    if (trace != nullptr) {
      const jaco::ArmSnapshot now = rig.controller->snapshot();
      *trace << "  " << i << " control " << static_cast<int>(now.control) << " stop "
             << jaco::to_string(now.last_stop) << " clear " << truth.margin_m << " part "
             << static_cast<int>(truth.capsule) << " box "
             << (truth.box != nullptr ? truth.box->name.view() : "") << " v";
      for (double v : rig.arm().joint_velocities()) *trace << ' ' << v;
      *trace << " q";
      for (double q : rig.arm().joints()) *trace << ' ' << q;
      *trace << '\n';
    }
    r.worst_clearance_m = std::min(r.worst_clearance_m, truth.margin_m);
    r.monitor_nodes += rig.controller->snapshot().monitor_nodes;
    if (truth.margin_m < 0.0) {
      r.ok = false;
      r.failure = where(i) + "the true arm reached " + std::to_string(-truth.margin_m * 1e3) +
                  " mm " + (truth.workspace ? "outside the workspace" : "into keep-out '") +
                  (truth.workspace ? "" : std::string(truth.box->name.view()) + "'");
    }
    if (!limits.joints.contains(rig.arm().joints())) {
      r.ok = false;
      r.failure = where(i) + "a joint passed its limit";
    }
    if (stop.active) {
      stop.link_lost = stop.link_lost || rig.controller->snapshot().fault;
      const std::int64_t took = rig.now() - stop.at;
      const bool in_silence =
          silent && rig.now() >= silent->first && stop.at <= silent->second + 50 * MS;
      if (!rig.arm().moving()) {
        r.worst_stop_ns = std::max(r.worst_stop_ns, took);
        stop.active = false;
      } else if (took > stop.bound && !in_silence && !stop.link_lost) {
        r.ok = false;
        r.failure = where(i) + "a stop took longer than its bound (" + std::to_string(took / MS) +
                    " ms > " + std::to_string(stop.bound / MS) + " ms)";
      }
    }
  }
  const jaco::ArmSnapshot end = rig.controller->snapshot();
  r.monitor_stops = end.monitor_stops;
  return r;
}

}  // namespace orthoflow::test
