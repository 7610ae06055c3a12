// The JACO's safety monitor (drivers/jaco/jaco_safety_monitor.hpp, docs/SAFETY.md): moves swept
// along their whole path (the plate a sampled check let through), the links, the fingers and a
// held object checked as well as the hand, a client's velocity stream stopped before the table on
// the simulated arm with physics (judged by the simulator's true joints), the firmware's HOME
// checked like any motion, and the guard that faults a silent arm on its own clock.
#include <gtest/gtest.h>

#include <iostream>
#include <limits>

#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_safety_monitor.hpp"
#include "tests/drivers/jaco/arm_truth.hpp"
#include "tests/drivers/jaco/jaco_test_rig.hpp"

namespace orthoflow::test {
namespace {

using jaco::ArmCommand;
using Kind = ArmCommand::Kind;
using Limit = jaco::SafetyViolation::Limit;

jaco::Box box_around(const Eigen::Vector3d& p, double half, const char* name,
                     jaco::BodyPart from = jaco::BodyPart::UPPER_ARM) {
  jaco::Box b;
  b.min = p - Eigen::Vector3d::Constant(half);
  b.max = p + Eigen::Vector3d::Constant(half);
  b.name.assign(name);
  b.from = from;
  return b;
}

jaco::JointAngles home_joints() {
  JacoRig probe;
  return probe.arm().joints();
}

// The user's report: a 5 mm plate across a 90 degree base turn. 32 samples along the path let the
// hand through; the sweep does not, and a target on that path is refused the same way.
TEST(JacoSafetyMonitor, AThinPlateAcrossALongMoveIsRefused) {
  jaco::SafetyLimits limits;
  jaco::Box plate;
  plate.min = {0.2, -0.025, 0.4};
  plate.max = {0.5, -0.020, 0.6};
  plate.name.assign("plate");
  ASSERT_TRUE(limits.add_keep_out(plate));
  const jaco::JointAngles from = home_joints();
  const jaco::JointAngles to{185.0, 167.5, 57.5, 240.0, 82.5, 75.0};
  auto r = jaco::check_joint_move(limits, from, to);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().limit, Limit::KEEP_OUT);
  EXPECT_EQ(r.error().box.view(), "plate");
  EXPECT_GT(r.error().ahead_s, 0.0);
  EXPECT_LT(r.error().ahead_s, 1.0);
  // Without the plate the same move is clear.
  EXPECT_TRUE(jaco::check_joint_move(jaco::SafetyLimits{}, from, to));
}

// The work bound holds whether or not the caller asks what the check cost (the controller does
// not): a base turn above a table closer than any budget can show clear is UNPROVEN after at most
// the budget, for a straight move and a firmware motion alike. The table's height is found by
// bisection between clear and touching.
TEST(JacoSafetyMonitor, TheWorkBoundHoldsWithoutACostCounter) {
  const jaco::JointAngles from = home_joints();
  const jaco::JointAngles to{185.0, 167.5, 57.5, 240.0, 82.5, 75.0};  // the base turns: z stays
  const auto limits_at = [](double top) {
    jaco::SafetyLimits limits;
    limits.sweep_resolution_m = 1e-7;
    jaco::Box table{{-0.9, -0.9, -0.5}, {0.9, 0.9, top}, core::FixedText<24>::from("table")};
    EXPECT_TRUE(limits.add_keep_out(table));
    return limits;
  };
  double clear = 0.0, touching = 0.4;
  ASSERT_TRUE(jaco::check_joint_move(limits_at(clear), from, to));
  ASSERT_FALSE(jaco::check_joint_move(limits_at(touching), from, to));
  bool found = false;
  for (int i = 0; i < 60 && !found; ++i) {
    const double top = 0.5 * (clear + touching);
    const jaco::SafetyLimits limits = limits_at(top);
    jaco::MonitorCost cost;
    auto counted = jaco::check_joint_move(limits, from, to, 0.0, {}, &cost);
    EXPECT_LE(cost.nodes, jaco::MAX_MONITOR_NODES);
    if (counted) {
      clear = top;
    } else if (counted.error().limit != Limit::UNPROVEN) {
      touching = top;
    } else {
      found = true;
      auto uncounted = jaco::check_joint_move(limits, from, to);
      ASSERT_FALSE(uncounted);
      EXPECT_EQ(uncounted.error().limit, Limit::UNPROVEN);
      jaco::MonitorCost firmware_cost;
      auto firmware = jaco::prove_firmware_motion(limits, from, to, 0.0, {}, &firmware_cost);
      EXPECT_LE(firmware_cost.nodes, jaco::MAX_FIRMWARE_NODES);
      auto firmware_uncounted = jaco::prove_firmware_motion(limits, from, to);
      EXPECT_EQ(bool(firmware), bool(firmware_uncounted));
      if (!firmware && !firmware_uncounted) {
        EXPECT_EQ(firmware.error().limit, firmware_uncounted.error().limit);
      }
    }
  }
  EXPECT_TRUE(found) << "no table height between " << clear << " and " << touching;
}

// A box the forearm sweeps through while the hand passes far from it: refused, naming the link.
TEST(JacoSafetyMonitor, LinksAreCheckedNotOnlyTheHand) {
  const jaco::JointAngles from = home_joints();
  jaco::JointAngles to = from;
  to[0] += 60.0;
  jaco::JointAngles middle = from;
  middle[0] += 30.0;
  const jaco::ChainFrames frames = jaco::forward_kinematics_frames(middle, jaco::jaco2_geometry());
  // The elbow: the end of the upper arm (DH row 2), far from the hand.
  const Eigen::Vector3d elbow = frames[2].translation();
  const Eigen::Vector3d hand = jaco::forward_kinematics(middle).translation();
  ASSERT_GT((elbow - hand).norm(), 0.15);
  jaco::SafetyLimits limits;
  ASSERT_TRUE(limits.add_keep_out(box_around(elbow, 0.01, "lamp")));
  auto r = jaco::check_joint_move(limits, from, to);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().limit, Limit::KEEP_OUT);
  EXPECT_EQ(r.error().box.view(), "lamp");
  EXPECT_TRUE(r.error().part == jaco::BodyPart::UPPER_ARM ||
              r.error().part == jaco::BodyPart::FOREARM)
      << jaco::to_string(r.error().part);
  EXPECT_NE(jaco::describe(r.error()).find("lamp"), std::string::npos);
}

// Open fingers reach further than closed ones; a held object further still.
TEST(JacoSafetyMonitor, FingersAndAHeldObjectAreChecked) {
  const jaco::JointAngles q = home_joints();
  // A 4 mm box beside the tool point, 58 mm off the axis: past the palm (its capsule ends 30 mm
  // behind the tool point, 60 mm round) and the closed fingers (25 mm round), inside the open
  // fingers' bundle (70 mm round, its end drawn back to 25 mm behind the tool point).
  const Eigen::Isometry3d tool = jaco::forward_kinematics(q);
  const Eigen::Vector3d point = tool * Eigen::Vector3d(0.058, 0.0, 0.0);
  jaco::SafetyLimits limits;
  ASSERT_TRUE(limits.add_keep_out(box_around(point, 0.002, "cup_rim")));
  EXPECT_TRUE(jaco::check_joint_move(limits, q, q, 0.0));
  auto open = jaco::check_joint_move(limits, q, q, 1.0);
  ASSERT_FALSE(open);
  EXPECT_EQ(open.error().part, jaco::BodyPart::FINGERTIPS);
  // A bottle held along the tool axis, 0.25 m long, past the fingertips: a box where only it goes.
  jaco::HeldCapsule bottle{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.25}, 0.035};
  const Eigen::Vector3d below = tool * Eigen::Vector3d(0.0, 0.0, 0.22);
  jaco::SafetyLimits shelf;
  ASSERT_TRUE(shelf.add_keep_out(box_around(below, 0.01, "shelf")));
  EXPECT_TRUE(jaco::check_joint_move(shelf, q, q, 0.0));
  auto held = jaco::check_joint_move(shelf, q, q, 0.0, bottle);
  ASSERT_FALSE(held);
  EXPECT_EQ(held.error().part, jaco::BodyPart::HELD_OBJECT);
}

// The way the shoulder (joint 2) turns to lower the hand at @p q.
std::pair<std::size_t, double> downward(const jaco::JointAngles& q) {
  const double z0 = jaco::forward_kinematics(q).translation().z();
  std::pair<std::size_t, double> best{0, 1.0};
  double drop = 0.0;
  for (std::size_t j = 1; j < 2; ++j) {
    for (double sign : {-1.0, 1.0}) {
      jaco::JointAngles p = q;
      p[j] += sign;
      const double d = z0 - jaco::forward_kinematics(p).translation().z();
      if (d > drop) {
        drop = d;
        best = {j, sign};
      }
    }
  }
  return best;
}

// One velocity command kept alive used to drive the hand through the table. Now every cycle is
// checked: the stream is stopped with the table named, and the true arm (braking with the
// simulator's physics) never reaches into it.
TEST(JacoSafetyMonitor, AVelocityStreamIsStoppedBeforeTheTable) {
  jaco::ControllerOptions options;
  const jaco::JointAngles q = home_joints();
  jaco::Box table;
  table.min = {-0.9, -0.9, -0.2};
  table.max = {0.9, 0.9, 0.15};  // under the shoulder (0.28 m), 0.36 m under the hand
  table.name.assign("table");
  ASSERT_TRUE(options.limits.add_keep_out(table));
  JacoRig rig(JacoRig::home_config(), options);
  const auto [joint, sign] = downward(q);
  ArmCommand v;
  v.kind = Kind::VELOCITY;
  double worst = 1.0;
  bool stopped = false;
  for (int i = 1; i <= 1000 && !stopped; ++i) {
    v.velocity = {};
    v.velocity[joint] = sign * std::min(25.0, 0.4 * i);  // the acceleration cap, then 25 deg/s
    auto accepted = rig.controller->submit(v);
    if (!accepted && i < 3) ADD_FAILURE() << jaco::to_string(accepted.error());
    rig.cycle(false);
    worst = std::min(worst, true_clearance(options.limits, rig.arm()).margin_m);
    stopped = rig.controller->snapshot().last_stop == jaco::StopReason::SAFETY;
  }
  ASSERT_TRUE(stopped) << "the stream was never stopped; refused "
                       << rig.controller->snapshot().refused << " last stop "
                       << jaco::to_string(rig.controller->snapshot().last_stop) << " joint "
                       << joint << " moved to " << rig.arm().joints()[joint] << " hand z "
                       << jaco::forward_kinematics(rig.arm().joints()).translation().z()
                       << " table " << table.max.z();
  const jaco::ArmSnapshot s = rig.controller->snapshot();
  EXPECT_EQ(s.violation.limit, Limit::KEEP_OUT);
  EXPECT_EQ(s.violation.box.view(), "table");
  EXPECT_GE(s.monitor_stops, 1U);
  // The stream is refused from now on, and the arm comes to rest short of the table.
  EXPECT_FALSE(rig.controller->submit(v));
  for (int i = 0; i < 100; ++i) {
    rig.cycle(false);
    worst = std::min(worst, true_clearance(options.limits, rig.arm()).margin_m);
  }
  EXPECT_FALSE(rig.arm().moving());
  EXPECT_GT(worst, 0.0) << "the true arm reached " << -worst << " m into the table";
}

// The firmware drives HOME itself and finishes it even if the link fails: the monitor starts it
// only when the whole box of joint ranges to the pose is clear, and checks each cycle of it like
// any motion (a held object taken mid-way, say).
TEST(JacoSafetyMonitor, HomingIsRefusedWhenItsWayCrossesAKeepOutAndCheckedEveryCycle) {
  simulation::SimJacoConfig config;
  config.start_state = jaco::ArmState::RETRACT_STANDBY;
  JacoRig retracted(config);
  const jaco::JointAngles start = retracted.arm().joints();
  jaco::ControllerOptions options;
  const jaco::JointAngles goal = options.home_joints;
  jaco::JointAngles middle;
  for (std::size_t j = 0; j < 6; ++j) middle[j] = 0.5 * (start[j] + goal[j]);
  const Eigen::Vector3d hand = jaco::forward_kinematics(middle).translation();
  ASSERT_TRUE(options.limits.add_keep_out(box_around(hand, 0.05, "tray")));
  JacoRig rig(config, options);
  ArmCommand home;
  home.kind = Kind::HOME;
  auto refused = rig.controller->submit(home);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().violation.box.view(), "tray");
  for (int i = 0; i < 20; ++i) rig.cycle(true);
  EXPECT_FALSE(rig.arm().last_motion_ns().has_value());
  // Each cycle of firmware motion: the envelope toward the goal at the measured speed.
  jaco::CycleIntent intent;
  intent.firmware = true;
  intent.firmware_goal = goal;
  intent.joints = start;
  for (std::size_t j = 0; j < 6; ++j)
    intent.velocity[j] = goal[j] > start[j] ? 30.0 : goal[j] < start[j] ? -30.0 : 0.0;
  jaco::SafetyLimits clear;
  EXPECT_TRUE(jaco::check_cycle(clear, intent));
  jaco::JointAngles ahead = start;  // where 0.1 s at that speed leads
  for (std::size_t j = 0; j < 6; ++j) ahead[j] += 0.1 * intent.velocity[j];
  jaco::SafetyLimits near = clear;
  ASSERT_TRUE(
      near.add_keep_out(box_around(jaco::forward_kinematics(ahead).translation(), 0.01, "cup")));
  auto stopped = jaco::check_cycle(near, intent);
  ASSERT_FALSE(stopped);
  EXPECT_EQ(stopped.error().box.view(), "cup");
}

// The default keep-outs (manipulation/arm_limits_file.cpp): the table under the base plate and
// the base column. HOME from the folded RETRACT pose passes close to both at the firmware's top
// speeds; the monitor proves every cycle of it within its budget.
TEST(JacoSafetyMonitor, HomingFromRetractPassesTheDefaultKeepOuts) {
  jaco::ControllerOptions options;
  jaco::Box table{{-0.9, -0.9, -0.2}, {0.9, 0.9, 0.0}, core::FixedText<24>::from("table")};
  jaco::Box base{{-0.075, -0.075, -0.1}, {0.075, 0.075, 0.16}, core::FixedText<24>::from("base")};
  base.from = jaco::BodyPart::FOREARM;
  ASSERT_TRUE(options.limits.add_keep_out(table));
  ASSERT_TRUE(options.limits.add_keep_out(base));
  simulation::SimJacoConfig config;
  config.start_state = jaco::ArmState::RETRACT_STANDBY;
  JacoRig rig(config, options);
  ArmCommand home;
  home.kind = Kind::HOME;
  ASSERT_TRUE(rig.controller->submit(home));
  std::uint64_t most = 0;
  double worst = 1.0;
  for (int i = 0; i < 3000 && rig.controller->snapshot().arm_state != jaco::ArmState::READY_STANDBY;
       ++i) {
    rig.cycle(true);
    most = std::max(most, rig.controller->snapshot().monitor_nodes);
    worst = std::min(worst, true_clearance(options.limits, rig.arm()).margin_m);
  }
  const jaco::ArmSnapshot s = rig.controller->snapshot();
  EXPECT_EQ(s.arm_state, jaco::ArmState::READY_STANDBY) << jaco::describe(s.violation);
  EXPECT_NE(s.last_stop, jaco::StopReason::SAFETY) << jaco::describe(s.violation);
  EXPECT_LE(most, jaco::MAX_MONITOR_NODES);
  EXPECT_GT(worst, 0.0);
  std::cout << "homing from retract: at most " << most << " monitor stretches in a cycle\n";
}

// The guard runs on its own clock: an arm that stops answering is FAULT within one period plus the
// transfer deadline, 30 ms at most, while the USB thread is still stuck in its transfer.
TEST(JacoSafetyMonitor, TheGuardFaultsASilentArmWithin30ms) {
  JacoRig rig;
  for (int i = 0; i < 5; ++i) rig.cycle(true);
  const std::int64_t last_reply = rig.controller->snapshot().last_reply_ns;
  ASSERT_GT(last_reply, 0);
  rig.arm();  // the arm goes silent now; the USB thread does not run (stuck in a transfer)
  std::int64_t faulted = -1;
  for (int ms = 0; ms < 100 && faulted < 0; ++ms) {
    rig.sim.run_for(std::chrono::milliseconds(1));
    if (ms % 2 == 1) rig.controller->guard(rig.now());  // the guard's 2 ms tick
    if (rig.controller->snapshot().fault) faulted = rig.now();
  }
  ASSERT_GE(faulted, 0);
  EXPECT_LE(faulted - last_reply, 30'000'000);
  // Nothing but a stop leaves a halted controller.
  ArmCommand v;
  v.kind = Kind::VELOCITY;
  EXPECT_FALSE(rig.controller->submit(v));
}

TEST(JacoSafetyMonitor, NonFiniteIntentsAreRefused) {
  jaco::SafetyLimits limits;
  jaco::CycleIntent intent;
  intent.joints = home_joints();
  EXPECT_TRUE(jaco::check_cycle(limits, intent));
  const double inf = std::numeric_limits<double>::infinity();
  for (double bad : {std::nan(""), inf, -inf}) {
    jaco::CycleIntent i = intent;
    i.command[2] = bad;
    auto r = jaco::check_cycle(limits, i);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().limit, Limit::NOT_FINITE);
    i = intent;
    i.held = {{0, 0, 0}, {0, 0, bad}, 0.02};
    EXPECT_FALSE(jaco::check_cycle(limits, i));
  }
  jaco::CycleIntent huge = intent;
  huge.command[0] = 1e300;
  auto r = jaco::check_cycle(limits, huge);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().limit, Limit::SPEED);
}

}  // namespace
}  // namespace orthoflow::test
