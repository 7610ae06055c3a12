// The JACO driver end to end against the simulated arm (simulation/devices/sim_jaco_transport.hpp)
// on simulated time: start-up, streamed joint and Cartesian moves, fingers, HOME / RETRACT from
// every start, the watchdog, the emergency stop, the safety refusals, unplug and bad replies. What
// the arm really did is read from the simulator's ground truth; what the driver sent, from the
// recording transport (jaco_test_rig.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "jaco_test_rig.hpp"

namespace orthoflow::test {
namespace {

using jaco::ArmCommand;
using Kind = ArmCommand::Kind;

ArmCommand move_to(const jaco::JointAngles& q, double speed = 1.0) {
  ArmCommand c;
  c.kind = Kind::MOVE_JOINTS;
  c.joints = q;
  c.speed_fraction = speed;
  return c;
}

jaco::JointAngles offset(jaco::JointAngles q, const std::array<double, 6>& d) {
  for (std::size_t j = 0; j < 6; ++j) q[j] += d[j];
  return q;
}

double max_abs(const std::array<double, 6>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// When the first @p command left the host at or after @p since (simulated time), or -1.
std::int64_t first_sent(const JacoRig& rig, jaco::Command command, std::int64_t since) {
  for (const auto& p : rig.recorder.sent)
    if (p.t_ns >= since && p.command() == command) return p.t_ns;
  return -1;
}

// The simulated arm's own stopping time after an erase leaves the host, from @p speed (deg/s): its
// command latency, its deceleration to rest, and a DSP cycle each for the packet to be taken, the
// last braking step and the transfer.
std::int64_t rest_after_ns(JacoRig& rig, double speed) {
  const simulation::SimJacoDynamics& d = rig.arm().config().dynamics;
  return d.command_latency_ns + static_cast<std::int64_t>(speed / d.decel_deg_s2 * 1e9) +
         3 * jaco::ARM_PERIOD_NS;
}

TEST(JacoControllerSim, StartUpTakesControlAndLeavesNothingToMove) {
  JacoRig rig;
  EXPECT_EQ(rig.controller->identity().model, jaco::Model::JACO2);
  EXPECT_TRUE(rig.controller->identity().firmware.dsp.dsp5());
  EXPECT_EQ(rig.controller->identity().client.serial.view(), "PJ00650019161750");
  EXPECT_TRUE(rig.arm().api_control());
  EXPECT_TRUE(rig.arm().joystick().is_release());
  EXPECT_EQ(rig.arm().fifo_size(), 0U);
  const auto s = rig.controller->snapshot();
  EXPECT_EQ(s.arm_state, jaco::ArmState::READY_STANDBY);
  for (std::size_t j = 0; j < 6; ++j) EXPECT_NEAR(s.joints[j], rig.arm().joints()[j], 1e-3);
  // Start-up sent no motion at all: no trajectory point, no joystick press.
  for (const auto& p : rig.recorder.sent) {
    EXPECT_NE(p.command(), jaco::Command::SEND_BASIC_TRAJECTORY);
    if (p.command() == jaco::Command::JOYSTICK) {
      jaco::JoystickState js;
      ASSERT_EQ(jaco::decode_joystick(p.bytes, js), jaco::PacketCheck::OK);
      EXPECT_TRUE(js.is_release());
    }
  }
}

TEST(JacoControllerSim, JointMoveArrivesWithinToleranceUnderTheSpeedCap) {
  JacoRig rig;
  const auto start = rig.arm().joints();
  const auto goal = offset(start, {20.0, -10.0, 8.0, 30.0, -15.0, 40.0});
  ASSERT_TRUE(rig.controller->submit(move_to(goal, 0.5)).has_value());
  const double cap = rig.controller->options().limits.max_joint_speed_deg_s * 0.5;
  double fastest = 0.0;
  int cycles = 0;
  for (; cycles < 1000; ++cycles) {
    rig.cycle(true);
    fastest = std::max(fastest, max_abs(rig.arm().joint_velocities()));
    if (cycles > 2 && rig.controller->snapshot().control == jaco::ControlState::IDLE) break;
  }
  const auto s = rig.controller->snapshot();
  EXPECT_EQ(s.last_stop, jaco::StopReason::REACHED);
  for (std::size_t j = 0; j < 6; ++j) EXPECT_NEAR(rig.arm().joints()[j], goal[j], 0.3) << j;
  EXPECT_LE(fastest, cap * 1.05);
  // 40 deg at 15 deg/s with 60 deg/s^2 ramps: about 2.9 s; allow settling.
  EXPECT_LT(cycles, 400);
  // Only angular velocity points were sent, every one within the cap.
  for (const auto& p : rig.recorder.sent) {
    if (p.command() != jaco::Command::SEND_BASIC_TRAJECTORY) continue;
    jaco::TrajectoryPoint point;
    ASSERT_EQ(jaco::decode_trajectory(p.bytes, point), jaco::PacketCheck::OK);
    EXPECT_EQ(point.type, jaco::PositionType::ANGULAR_VELOCITY);
    for (float v : point.target) EXPECT_LE(std::abs(v), cap * (1.0 + 1e-6));
  }
  for (int i = 0; i < 20; ++i) rig.cycle(true);
  EXPECT_FALSE(rig.arm().moving());
}

TEST(JacoControllerSim, PoseMoveReachesThePoseWithinAMillimetre) {
  JacoRig rig;
  const auto target_joints = offset(rig.arm().joints(), {-15.0, 10.0, -10.0, 20.0, 10.0, -25.0});
  const Eigen::Isometry3d target = jaco::forward_kinematics(target_joints);
  ArmCommand c;
  c.kind = Kind::MOVE_POSE;
  c.pose = jaco::to_pose(target);
  ASSERT_TRUE(rig.controller->submit(c).has_value());
  rig.run_until_idle(2000);
  EXPECT_EQ(rig.controller->snapshot().last_stop, jaco::StopReason::REACHED);
  const Eigen::Isometry3d reached = jaco::forward_kinematics(rig.arm().joints());
  EXPECT_LT((reached.translation() - target.translation()).norm(), 1e-3);
  const double angle = Eigen::AngleAxisd(reached.linear().transpose() * target.linear()).angle();
  EXPECT_LT(angle, 0.5 * M_PI / 180.0);
}

TEST(JacoControllerSim, FingersCloseAndOpen) {
  JacoRig rig;
  ArmCommand c;
  c.kind = Kind::MOVE_FINGERS;
  c.fingers = {6000.0, 6000.0, 6000.0};
  ASSERT_TRUE(rig.controller->submit(c).has_value());
  for (int i = 0; i < 600; ++i) rig.cycle(true);
  for (double f : rig.arm().fingers()) EXPECT_NEAR(f, 6000.0, 0.02 * 6400.0);
  c.fingers = {0.0, 0.0, 0.0};
  ASSERT_TRUE(rig.controller->submit(c).has_value());
  for (int i = 0; i < 600; ++i) rig.cycle(true);
  for (double f : rig.arm().fingers()) EXPECT_NEAR(f, 0.0, 0.02 * 6400.0);
  c.fingers = {7000.0, 0.0, 0.0};
  const auto refused = rig.controller->submit(c);
  ASSERT_FALSE(refused.has_value());
  EXPECT_EQ(refused.error().violation.limit, jaco::SafetyViolation::Limit::FINGER);
}

// A grasped object stops the fingers short of their goal: the controller sees them stall, ends the
// goal there and says so (the execution manager takes that as closed on the object), instead of
// pushing against it for ever.
TEST(JacoControllerSim, FingersStoppedByAnObjectEndTheirGoalAsBlocked) {
  JacoRig rig;
  ArmCommand c;
  c.kind = Kind::MOVE_FINGERS;
  c.fingers = {6000.0, 6000.0, 6000.0};
  rig.arm().set_finger_stop(3500.0);
  ASSERT_TRUE(rig.controller->submit(c).has_value());
  rig.cycle(true);
  EXPECT_TRUE(rig.controller->snapshot().fingers_moving);
  for (int i = 0; i < 600; ++i) rig.cycle(true);
  jaco::ArmSnapshot s = rig.controller->snapshot();
  for (double f : rig.arm().fingers()) EXPECT_NEAR(f, 3500.0, 1.0);
  EXPECT_FALSE(s.fingers_moving) << "the goal ended where they stalled";
  EXPECT_TRUE(s.fingers_blocked);
  EXPECT_EQ(s.control, jaco::ControlState::IDLE);
  EXPECT_FALSE(s.fault);
  // Opening is not blocked, and a goal that is reached is not blocked.
  c.fingers = {0.0, 0.0, 0.0};
  ASSERT_TRUE(rig.controller->submit(c).has_value());
  for (int i = 0; i < 600; ++i) rig.cycle(true);
  s = rig.controller->snapshot();
  for (double f : rig.arm().fingers()) EXPECT_NEAR(f, 0.0, 0.02 * 6400.0);
  EXPECT_FALSE(s.fingers_blocked);
  EXPECT_FALSE(s.fingers_moving);
  // Slow fingers are not a stall: nothing in the way, the goal is reached.
  rig.arm().set_finger_stop(std::nullopt);
  c.fingers = {6000.0, 6000.0, 6000.0};
  ASSERT_TRUE(rig.controller->submit(c).has_value());
  for (int i = 0; i < 600; ++i) rig.cycle(true);
  for (double f : rig.arm().fingers()) EXPECT_NEAR(f, 6000.0, 0.02 * 6400.0);
  EXPECT_FALSE(rig.controller->snapshot().fingers_blocked);
}

// The watchdog: after the client's last word the driver has sent its erase within 100 ms of
// simulated time, and the arm (with its own deceleration) is at rest within its stopping time after
// that, measured on the simulator's own record of when a joint last moved.
TEST(JacoControllerSim, WatchdogStopsTheArmWithin100msOfTheLastCommand) {
  JacoRig rig;
  const auto goal = offset(rig.arm().joints(), {60.0, 0.0, 0.0, 60.0, 0.0, 60.0});
  ASSERT_TRUE(rig.controller->submit(move_to(goal)).has_value());
  for (int i = 0; i < 50; ++i) rig.cycle(true);  // 0.5 s of motion, fed every cycle
  ASSERT_TRUE(rig.arm().moving());
  const double speed = rig.controller->options().limits.max_joint_speed_deg_s;  // at most
  rig.controller->keep_alive();
  const std::int64_t last = rig.now();
  for (int i = 0; i < 80; ++i) rig.cycle(false);  // the client is gone
  const std::int64_t erased = first_sent(rig, jaco::Command::ERASE_TRAJECTORIES, last);
  ASSERT_GE(erased, 0);
  EXPECT_LE(erased, last + 100'000'000);
  ASSERT_TRUE(rig.arm().last_motion_ns().has_value());
  EXPECT_LE(*rig.arm().last_motion_ns(), erased + rest_after_ns(rig, speed));
  EXPECT_FALSE(rig.arm().moving());
  EXPECT_EQ(rig.arm().fifo_size(), 0U);
  const auto s = rig.controller->snapshot();
  EXPECT_EQ(s.last_stop, jaco::StopReason::WATCHDOG);
  EXPECT_EQ(s.watchdog_stops, 1U);
}

// Same with the arm's FIFO full: 2000 velocity points (20 s of motion) pushed behind the driver's
// back, as a runaway client would. The watchdog's erase empties it.
TEST(JacoControllerSim, WatchdogStopsTheArmWithAFullFifo) {
  JacoRig rig;
  jaco::TrajectoryPoint point;
  point.type = jaco::PositionType::ANGULAR_VELOCITY;
  point.hand_mode = jaco::HandMode::NO_MOVEMENT;
  point.target = {5.0F, 0.0F, 0.0F, 5.0F, 0.0F, 5.0F};
  const jaco::Packet packet = jaco::encode_trajectory(point);
  ASSERT_TRUE(rig.controller->submit(move_to(offset(rig.arm().joints(), {1, 0, 0, 0, 0, 0}))));
  for (std::size_t i = 0; i < jaco::TRAJECTORY_FIFO; ++i) rig.arm().receive(packet, rig.now());
  rig.arm().reset_replies();
  // The points act after the arm's command latency.
  rig.arm().step(rig.now() + rig.arm().config().dynamics.command_latency_ns + jaco::ARM_PERIOD_NS);
  EXPECT_GE(rig.arm().fifo_size(), jaco::TRAJECTORY_FIFO - 3);
  rig.controller->keep_alive();
  const std::int64_t last = rig.now();
  for (int i = 0; i < 40; ++i) rig.cycle(false);
  EXPECT_EQ(rig.arm().fifo_size(), 0U);
  EXPECT_FALSE(rig.arm().moving());
  const std::int64_t erased = first_sent(rig, jaco::Command::ERASE_TRAJECTORIES, last);
  ASSERT_GE(erased, 0);
  EXPECT_LE(erased, last + 100'000'000);
  ASSERT_TRUE(rig.arm().last_motion_ns().has_value());
  EXPECT_LE(*rig.arm().last_motion_ns(), erased + rest_after_ns(rig, 5.0));
}

TEST(JacoControllerSim, EmergencyStopHoldsUntilReset) {
  JacoRig rig;
  const auto goal = offset(rig.arm().joints(), {60.0, 0.0, 0.0, 0.0, 0.0, 60.0});
  ASSERT_TRUE(rig.controller->submit(move_to(goal)).has_value());
  for (int i = 0; i < 40; ++i) rig.cycle(true);
  ASSERT_TRUE(rig.arm().moving());
  const double speed = max_abs(rig.arm().joint_velocities());
  rig.controller->estop();
  const std::int64_t pulled = rig.now();
  for (int i = 0; i < 60; ++i) rig.cycle(true);
  // No motion packet after the pull; the erase in the next cycle; rest within the arm's own
  // stopping time.
  const std::int64_t erased = first_sent(rig, jaco::Command::ERASE_TRAJECTORIES, pulled);
  ASSERT_GE(erased, 0);
  EXPECT_LE(erased, pulled + jaco::ARM_PERIOD_NS);
  EXPECT_LT(first_sent(rig, jaco::Command::SEND_BASIC_TRAJECTORY, pulled), 0);
  EXPECT_LE(*rig.arm().last_motion_ns(), erased + rest_after_ns(rig, speed));
  auto refused = rig.controller->submit(move_to(goal));
  ASSERT_FALSE(refused.has_value());
  EXPECT_EQ(refused.error().code, jaco::JacoError::Code::ESTOP);
  // Points that reach the FIFO while latched are erased again, cycle after cycle.
  jaco::TrajectoryPoint point;
  point.type = jaco::PositionType::ANGULAR_VELOCITY;
  point.target = {5.0F, 0.0F, 0.0F, 0.0F, 0.0F, 0.0F};
  for (int i = 0; i < 100; ++i) rig.arm().receive(jaco::encode_trajectory(point), rig.now());
  rig.arm().reset_replies();
  for (int i = 0; i < 100; ++i) rig.cycle(true);
  EXPECT_EQ(rig.arm().fifo_size(), 0U);
  EXPECT_TRUE(rig.controller->snapshot().estop);
  EXPECT_EQ(rig.controller->snapshot().control, jaco::ControlState::ESTOP);
  ASSERT_TRUE(rig.controller->reset_estop().has_value());
  rig.cycle(true);
  EXPECT_FALSE(rig.controller->snapshot().estop);
  ASSERT_TRUE(rig.controller->submit(move_to(goal)).has_value());
  rig.run_until_idle(2000);
  EXPECT_EQ(rig.controller->snapshot().last_stop, jaco::StopReason::REACHED);
}

// A sweep over joint 2's limits: every target inside is accepted, every one outside refused by
// name, and no refused target ever produces a packet that moves the arm.
TEST(JacoControllerSim, JointLimitSweepRefusesEveryTargetOutside) {
  JacoRig rig;
  const auto limits = rig.controller->options().limits.joints;
  const auto here = rig.arm().joints();
  for (double d : {-5.0, -0.01, 0.0, 0.01, 5.0}) {
    for (bool upper : {false, true}) {
      auto q = here;
      q[1] = (upper ? limits.upper[1] : limits.lower[1]) + (upper ? d : -d);
      const bool outside = d > 0.0;
      const std::size_t before = rig.recorder.sent.size();
      auto result = rig.controller->submit(move_to(q));
      if (outside) {
        ASSERT_FALSE(result.has_value()) << q[1];
        EXPECT_EQ(result.error().code, jaco::JacoError::Code::REFUSED);
        if (result.error().violation.limit == jaco::SafetyViolation::Limit::JOINT_LIMIT) {
          EXPECT_EQ(result.error().violation.joint, 1U);
          EXPECT_NE(jaco::to_string(result.error()).find("joint 2"), std::string::npos);
        }
        rig.cycle(true);
        for (std::size_t i = before; i < rig.recorder.sent.size(); ++i)
          EXPECT_NE(rig.recorder.sent[i].command(), jaco::Command::SEND_BASIC_TRAJECTORY);
      } else if (result.has_value()) {
        (void)rig.controller->submit(ArmCommand{Kind::STOP});
        rig.cycle(true);
      } else {
        // On the limit the hand may still leave the workspace: a refusal must name that instead.
        EXPECT_NE(result.error().violation.limit, jaco::SafetyViolation::Limit::JOINT_LIMIT);
      }
    }
  }
}

TEST(JacoControllerSim, RefusesNonFiniteUnreachableKeepOutAndFastCommands) {
  jaco::ControllerOptions options;
  JacoRig probe;
  const auto here = probe.arm().joints();
  const auto goal = offset(here, {40.0, 0.0, 0.0, 0.0, 0.0, 0.0});
  // A keep-out box around the middle of that move's hand path.
  jaco::JointAngles middle = offset(here, {20.0, 0.0, 0.0, 0.0, 0.0, 0.0});
  const Eigen::Vector3d p = jaco::forward_kinematics(middle).translation();
  jaco::Box box;
  box.min = p - Eigen::Vector3d::Constant(0.03);
  box.max = p + Eigen::Vector3d::Constant(0.03);
  box.name.assign("camera");
  ASSERT_TRUE(options.limits.add_keep_out(box));
  JacoRig rig(JacoRig::home_config(), options);
  using Limit = jaco::SafetyViolation::Limit;
  const auto limit_of = [&](const ArmCommand& c) {
    auto r = rig.controller->submit(c);
    EXPECT_FALSE(r.has_value());
    return r.has_value() ? Limit::NOT_FINITE : r.error().violation.limit;
  };
  EXPECT_EQ(limit_of(move_to(goal)), Limit::KEEP_OUT);
  auto nan = here;
  nan[3] = std::nan("");
  EXPECT_EQ(limit_of(move_to(nan)), Limit::NOT_FINITE);
  auto inf = here;
  inf[0] = INFINITY;
  EXPECT_EQ(limit_of(move_to(inf)), Limit::NOT_FINITE);
  ArmCommand far;
  far.kind = Kind::MOVE_POSE;
  far.pose.position = {0.85, 0.85, 0.3};  // inside the box, out of reach
  EXPECT_EQ(limit_of(far), Limit::UNREACHABLE);
  far.pose.position = {2.0, 0.0, 0.5};
  EXPECT_EQ(limit_of(far), Limit::WORKSPACE);
  far.pose.position = {0.3, 0.3, std::nan("")};
  EXPECT_EQ(limit_of(far), Limit::NOT_FINITE);
  ArmCommand fast;
  fast.kind = Kind::VELOCITY;
  fast.velocity = {0.0, 0.0, 0.0, 0.0, 0.0, 45.0};
  EXPECT_EQ(limit_of(fast), Limit::SPEED);
  fast.velocity = {0.0, 0.0, 0.0, 0.0, 0.0, 5.0};  // 0 -> 5 deg/s in 10 ms = 500 deg/s^2
  EXPECT_EQ(limit_of(fast), Limit::ACCELERATION);
  ArmCommand speed = move_to(here, 1.5);
  EXPECT_EQ(limit_of(speed), Limit::SPEED);
  // Nothing refused moved the arm.
  for (int i = 0; i < 10; ++i) rig.cycle(true);
  EXPECT_FALSE(rig.arm().last_motion_ns().has_value());
  EXPECT_GE(rig.controller->snapshot().refused, 8U);
}

TEST(JacoControllerSim, ClientStreamedVelocityMovesAndStopsWithTheStream) {
  JacoRig rig;
  const double start = rig.arm().joints()[5];
  ArmCommand v;
  v.kind = Kind::VELOCITY;
  for (int i = 1; i <= 100; ++i) {  // ramp to 10 deg/s at 40 deg/s^2 (the cap), then hold
    v.velocity = {0.0, 0.0, 0.0, 0.0, 0.0, std::min(10.0, 0.4 * i)};
    ASSERT_TRUE(rig.controller->submit(v).has_value()) << i;
    rig.cycle(false);
  }
  EXPECT_GT(rig.arm().joints()[5] - start, 5.0);
  const std::int64_t last = rig.now();
  for (int i = 0; i < 40; ++i) rig.cycle(false);
  const std::int64_t erased = first_sent(rig, jaco::Command::ERASE_TRAJECTORIES, last);
  ASSERT_GE(erased, 0);
  EXPECT_LE(erased, last + 100'000'000);
  EXPECT_LE(*rig.arm().last_motion_ns(), erased + rest_after_ns(rig, 10.0));
  EXPECT_EQ(rig.controller->snapshot().last_stop, jaco::StopReason::WATCHDOG);
}

// A stream may always slow down at once (a stop is never refused): the submit's early check
// follows the monitor's rule, so 10 deg/s -> 1 deg/s in one period is accepted, while speeding up
// as fast is refused.
TEST(JacoControllerSim, AStreamMaySlowDownAtOnceButNotSpeedUpAtOnce) {
  JacoRig rig;
  ArmCommand v;
  v.kind = Kind::VELOCITY;
  for (int i = 1; i <= 30; ++i) {
    v.velocity = {0.0, 0.0, 0.0, 0.0, 0.0, std::min(10.0, 0.4 * i)};
    ASSERT_TRUE(rig.controller->submit(v).has_value()) << i;
    rig.cycle(false);
  }
  v.velocity = {0.0, 0.0, 0.0, 0.0, 0.0, 1.0};
  EXPECT_TRUE(rig.controller->submit(v).has_value());
  rig.cycle(false);
  v.velocity = {0.0, 0.0, 0.0, 0.0, 0.0, 10.0};
  auto fast = rig.controller->submit(v);
  ASSERT_FALSE(fast.has_value());
  EXPECT_EQ(fast.error().violation.limit, jaco::SafetyViolation::Limit::ACCELERATION);
}

TEST(JacoControllerSim, HomesFromNoinitAndRefusesMotionBefore) {
  simulation::SimJacoConfig config;  // power-up: NOINIT
  JacoRig rig(config);
  EXPECT_EQ(rig.controller->snapshot().arm_state, jaco::ArmState::NOINIT);
  auto refused = rig.controller->submit(move_to(rig.arm().joints()));
  ASSERT_FALSE(refused.has_value());
  EXPECT_EQ(refused.error().code, jaco::JacoError::Code::INVALID_STATE);
  ASSERT_TRUE(rig.controller->submit(ArmCommand{Kind::HOME}).has_value());
  rig.run_until_idle(3000);
  rig.cycle(true);  // the release acts after the arm's command latency
  rig.cycle(true);
  const auto s = rig.controller->snapshot();
  EXPECT_EQ(s.last_stop, jaco::StopReason::REACHED);
  EXPECT_EQ(s.arm_state, jaco::ArmState::READY_STANDBY);
  EXPECT_EQ(rig.arm().state(), jaco::ArmState::READY_STANDBY);
  EXPECT_TRUE(rig.arm().joystick().is_release());
}

TEST(JacoControllerSim, RetractsFromHomeAndHomesBack) {
  JacoRig rig;
  ASSERT_TRUE(rig.controller->submit(ArmCommand{Kind::RETRACT}).has_value());
  rig.run_until_idle(3000);
  rig.cycle(true);  // the release acts after the arm's command latency
  rig.cycle(true);
  EXPECT_EQ(rig.arm().state(), jaco::ArmState::RETRACT_STANDBY);
  EXPECT_TRUE(rig.arm().joystick().is_release());
  ASSERT_TRUE(rig.controller->submit(ArmCommand{Kind::HOME}).has_value());
  rig.run_until_idle(3000);
  EXPECT_EQ(rig.arm().state(), jaco::ArmState::READY_STANDBY);
}

TEST(JacoControllerSim, RetractFromNormalIsRefused) {
  simulation::SimJacoConfig config;
  config.start_state = jaco::ArmState::NORMAL;
  config.start_joints = jaco::JointAngles{260.0, 180.0, 70.0, 240.0, 90.0, 60.0};
  JacoRig rig(config);
  auto r = rig.controller->submit(ArmCommand{Kind::RETRACT});
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, jaco::JacoError::Code::INVALID_STATE);
}

TEST(JacoControllerSim, AnArmThatNeverLeavesNoinitTimesOutAndIsReleased) {
  simulation::SimJacoConfig config;
  config.faults.never_leave_noinit = true;
  jaco::ControllerOptions options;
  options.home_timeout_ns = 2'000'000'000;
  JacoRig rig(config, options);
  ASSERT_TRUE(rig.controller->submit(ArmCommand{Kind::HOME}).has_value());
  const int cycles = rig.run_until_idle(1000);
  EXPECT_LT(cycles, 300);
  rig.cycle(true);  // the release acts after the arm's command latency
  rig.cycle(true);
  EXPECT_EQ(rig.controller->snapshot().last_stop, jaco::StopReason::HOME_TIMEOUT);
  EXPECT_TRUE(rig.arm().joystick().is_release());
}

// DSP >= 5 sometimes ignores a joystick packet: the press goes out twice, 100 ms apart on the
// driver's clock; on a DSP 4 arm it goes out once.
TEST(JacoControllerSim, Dsp5SendsThePressTwice100msApart) {
  for (bool dsp5 : {true, false}) {
    simulation::SimJacoConfig config =
        dsp5 ? simulation::SimJacoConfig{} : simulation::sim_jaco_v1_config();
    config.start_state = jaco::ArmState::NOINIT;
    JacoRig rig(config);
    rig.recorder.sent.clear();
    ASSERT_TRUE(rig.controller->submit(ArmCommand{Kind::HOME}).has_value());
    rig.run_until_idle(3000);
    EXPECT_EQ(rig.arm().state(), jaco::ArmState::READY_STANDBY) << dsp5;
    std::vector<std::int64_t> presses;
    for (const auto& p : rig.recorder.sent) {
      if (p.command() != jaco::Command::JOYSTICK) continue;
      jaco::JoystickState js;
      ASSERT_EQ(jaco::decode_joystick(p.bytes, js), jaco::PacketCheck::OK);
      if (js.buttons[jaco::HOME_BUTTON] == 1) presses.push_back(p.t_ns);
    }
    ASSERT_EQ(presses.size(), dsp5 ? 2U : 1U) << dsp5;
    if (dsp5) {
      EXPECT_GE(presses[1] - presses[0], 100'000'000);
      EXPECT_LT(presses[1] - presses[0], 120'000'000);
    }
  }
}

TEST(JacoControllerSim, UnplugMidMotionFaultsWithinOneCycleAndRefusesUntilReinitialised) {
  JacoRig rig;
  const auto goal = offset(rig.arm().joints(), {40.0, 0.0, 0.0, 0.0, 0.0, 0.0});
  ASSERT_TRUE(rig.controller->submit(move_to(goal)).has_value());
  for (int i = 0; i < 30; ++i) rig.cycle(true);
  rig.sim.unplug(0);
  rig.cycle(true);
  auto s = rig.controller->snapshot();
  EXPECT_TRUE(s.fault);
  EXPECT_EQ(s.control, jaco::ControlState::FAULT);
  EXPECT_EQ(s.fault_error.usb.code, drivers::UsbError::Code::NO_DEVICE);
  auto r = rig.controller->submit(move_to(goal));
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, jaco::JacoError::Code::FAULT);
  // The arm, cut off, ran out of streamed points at once.
  rig.sim.run_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(rig.arm().moving());
  rig.sim.replug(0);
  auto devices = jaco::list_arms(rig.recorder);
  ASSERT_TRUE(devices.has_value());
  ASSERT_EQ(devices.value().size(), 1U);
  ASSERT_TRUE(rig.controller->reinitialise(devices.value().front()).has_value());
  EXPECT_FALSE(rig.controller->snapshot().fault);
  ASSERT_TRUE(rig.controller->submit(move_to(goal)).has_value());
  rig.run_until_idle(2000);
  EXPECT_EQ(rig.controller->snapshot().last_stop, jaco::StopReason::REACHED);
}

// Bad replies: reads are asked again, but a motion command whose reply is bad faults the
// controller. Whatever happens, the arm never moves past the requested target or above the cap.
TEST(JacoControllerSim, GarbageRepliesNeverMoveTheArmBeyondTheCommand) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    simulation::SimJacoConfig config = JacoRig::home_config();
    config.fault_seed = seed;
    config.faults.garbage_reply_rate = 0.01;
    config.faults.wrong_command_rate = 0.01;
    config.faults.corrupt_body_rate = 0.01;
    std::unique_ptr<JacoRig> rig;
    try {
      rig = std::make_unique<JacoRig>(config);
    } catch (const std::runtime_error&) {
      continue;  // start-up itself refused a bad reply: a clear error, nothing moved
    }
    const auto start = rig->arm().joints();
    const auto goal = offset(start, {25.0, 0.0, 0.0, 0.0, 0.0, 0.0});
    if (!rig->controller->submit(move_to(goal)).has_value()) continue;
    double fastest = 0.0;
    for (int i = 0; i < 500; ++i) {
      rig->cycle(true);
      fastest = std::max(fastest, max_abs(rig->arm().joint_velocities()));
      EXPECT_LE(rig->arm().joints()[0], goal[0] + 0.5) << seed;
      EXPECT_GE(rig->arm().joints()[0], start[0] - 0.5) << seed;
    }
    EXPECT_LE(fastest, rig->controller->options().limits.max_joint_speed_deg_s * 1.05) << seed;
    const auto s = rig->controller->snapshot();
    EXPECT_TRUE(s.fault || s.last_stop == jaco::StopReason::REACHED) << seed;
    EXPECT_FALSE(rig->arm().moving()) << seed;
  }
}

TEST(JacoControllerSim, SameCommandsGiveTheSameTrajectory) {
  const auto run = [] {
    JacoRig rig;
    const auto goal = offset(rig.arm().joints(), {10.0, 5.0, -5.0, 10.0, 5.0, 10.0});
    (void)rig.controller->submit(move_to(goal, 0.7));
    rig.run_until_idle(1000);
    return rig.arm().joints();
  };
  EXPECT_EQ(run(), run());
}

}  // namespace
}  // namespace orthoflow::test
