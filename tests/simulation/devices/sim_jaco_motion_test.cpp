// The simulated JACO's motion (SimJacoArm behind SimJacoTransport), driven through the USB seam
// with packets from drivers/jaco/jaco_protocol.hpp: the trajectory FIFO, velocity streams, the
// latched joystick, erase, API control, speed limits, fingers and the Cartesian pose. Replies and
// the HOME / RETRACT button: sim_jaco_test.cpp.
#include <algorithm>
#include <cmath>

#include "sim_jaco_test_support.hpp"

namespace orthoflow::simulation::test {
namespace {

using S = jaco::ArmState;
using C = jaco::Command;

TEST(SimJaco, TrajectoryFifoHolds2000PointsConsumedOneEvery10Ms) {
  SimJacoArm arm(ready_config());
  arm.receive(jaco::make_plain_command(C::START_API_CONTROL), 0);
  const double j1 = arm.joints()[0];
  for (int i = 0; i < 2005; ++i) arm.receive(jaco::encode_trajectory(angular_velocity(0, 1.0F)), 0);
  EXPECT_EQ(arm.fifo_size(), 2000U);
  EXPECT_EQ(arm.counters().points_queued, 2000U);
  EXPECT_EQ(arm.counters().points_dropped, 5U);
  EXPECT_EQ(arm.counters().replies_lost, 2006U - SIM_JACO_REPLY_QUEUE);  // nobody read them
  arm.step(9 * MS);
  EXPECT_EQ(arm.fifo_size(), 2000U);
  arm.step(10 * MS);
  EXPECT_EQ(arm.fifo_size(), 1999U);
  arm.step(1000 * MS);
  EXPECT_EQ(arm.fifo_size(), 1900U);
  arm.step(30'000 * MS);
  EXPECT_EQ(arm.fifo_size(), 0U);
  EXPECT_EQ(arm.counters().points_completed, 2000U);
  EXPECT_NEAR(arm.joints()[0], j1 + 20.0, 1e-9);  // 2000 cycles x 10 ms x 1 deg/s
  EXPECT_EQ(*arm.last_motion_ns(), 20'000 * MS);
  EXPECT_EQ(arm.state(), S::NORMAL);
}

TEST(SimJaco, PositionPointMovesEachJointAtItsTopSpeedThenPops) {
  const SimJacoConfig c = ready_config();
  JacoRig rig(c);
  rig.plain(C::START_API_CONTROL);
  jaco::JointAngles target = c.home_joints;
  target[0] += 30.0;
  target[4] -= 12.0;
  rig.point(angular_position(target));
  EXPECT_EQ(rig.nine(C::GET_ANG_COMMAND).values[0], static_cast<float>(target[0]));
  double top0 = 0.0, top4 = 0.0;
  for (int i = 0; i < 120; ++i) {
    rig.wait(10ms);
    top0 = std::max(top0, std::abs(rig.arm().joint_velocities()[0]));
    top4 = std::max(top4, std::abs(rig.arm().joint_velocities()[4]));
  }
  EXPECT_NEAR(top0, 36.0, 1e-6);
  EXPECT_NEAR(top4, 48.0, 1e-6);
  EXPECT_NEAR(rig.arm().joints()[0], static_cast<float>(target[0]), 1e-9);
  EXPECT_EQ(rig.arm().fifo_size(), 0U);
  EXPECT_EQ(rig.arm().counters().points_completed, 1U);
  // Joint 1 needed ceil(30 / 0.36) = 84 cycles.
  EXPECT_FALSE(rig.arm().moving());
  // Out of limits (joint 2 in [47, 313]): dropped at the head.
  jaco::JointAngles bad = c.home_joints;
  bad[1] = 20.0;
  rig.point(angular_position(bad));
  rig.wait(20ms);
  EXPECT_EQ(rig.arm().counters().points_rejected, 1U);
}

TEST(SimJaco, VelocityPointsStopWhenTheStreamStopsAndAFastStreamQueues) {
  JacoRig rig;
  rig.plain(C::START_API_CONTROL);
  const double j2 = rig.arm().joints()[1];
  std::int64_t last_send = 0;
  for (int i = 0; i < 50; ++i) {  // 100 Hz: 2 ms exchange + 8 ms
    rig.point(angular_velocity(1, 20.0F));
    last_send = rig.now();
    rig.wait(8ms);
  }
  rig.wait(30ms);
  EXPECT_FALSE(rig.arm().moving());
  EXPECT_LE(*rig.arm().last_motion_ns() - last_send, 10 * MS);
  EXPECT_NEAR(rig.arm().joints()[1], j2 + 10.0, 1e-6);  // 50 x 10 ms x 20 deg/s
  // Back to back (2 ms each) the FIFO fills: 300 points keep the arm moving long after.
  for (int i = 0; i < 300; ++i) rig.point(angular_velocity(1, -20.0F));
  const std::size_t queued = rig.arm().fifo_size();
  EXPECT_GT(queued, 200U);
  rig.wait(std::chrono::milliseconds(static_cast<std::int64_t>(10 * queued) - 50));
  EXPECT_TRUE(rig.arm().moving());
  rig.wait(100ms);
  EXPECT_FALSE(rig.arm().moving());
  EXPECT_NEAR(rig.arm().joints()[1], j2 + 10.0 - 60.0, 1e-6);
}

TEST(SimJaco, LatchedJoystickKeepsMovingUntilReleased) {
  JacoRig rig;
  rig.plain(C::START_API_CONTROL);
  rig.plain(C::SET_CONTROL_ANGULAR);
  const double j4 = rig.arm().joints()[3];
  rig.joystick(axes(3, 2.5F));  // clamped to 1: joint 4 at its top speed
  rig.wait(2s);
  EXPECT_TRUE(rig.arm().moving());
  EXPECT_NEAR(rig.arm().joint_velocities()[3], 48.0, 1e-6);
  EXPECT_NEAR(rig.arm().joints()[3], j4 + 48.0 * 2.0, 48.0 * 0.03);
  EXPECT_FLOAT_EQ(rig.arm().joystick().axes[3], 2.5F);
  rig.joystick(axes(3, -0.5F));
  rig.wait(20ms);
  EXPECT_NEAR(rig.arm().joint_velocities()[3], -24.0, 1e-6);
  rig.joystick({});
  const std::int64_t released = rig.now();
  rig.wait(100ms);
  EXPECT_FALSE(rig.arm().moving());
  EXPECT_LE(*rig.arm().last_motion_ns(), released + 10 * MS);
  EXPECT_EQ(rig.arm().state(), S::NORMAL);
}

TEST(SimJaco, EraseStopsMotionAndEmptiesTheFifo) {
  const SimJacoConfig c = ready_config();
  JacoRig rig(c);
  rig.plain(C::START_API_CONTROL);
  jaco::JointAngles far = c.home_joints;
  far[0] += 90.0;
  for (int i = 0; i < 3; ++i) rig.point(angular_position(far));
  rig.wait(100ms);
  EXPECT_TRUE(rig.arm().moving());
  rig.plain(C::ERASE_TRAJECTORIES);
  const std::int64_t erased = rig.now();
  rig.wait(10ms);
  EXPECT_FALSE(rig.arm().moving());
  EXPECT_LE(*rig.arm().last_motion_ns(), erased + 10 * MS);
  EXPECT_EQ(rig.arm().fifo_size(), 0U);
  EXPECT_EQ(rig.arm().counters().points_erased, 3U);
  EXPECT_EQ(rig.nine(C::GET_ANG_COMMAND).values[0], static_cast<float>(rig.arm().joints()[0]));
}

TEST(SimJaco, NoMotionWithoutApiControlOrBeforeInit) {
  const SimJacoConfig c = ready_config();
  JacoRig rig(c);
  jaco::JointAngles target = c.home_joints;
  target[0] += 10.0;
  rig.point(angular_position(target));
  rig.joystick(axes(0, 1.0F));
  rig.wait(500ms);
  EXPECT_FALSE(rig.arm().last_motion_ns());
  EXPECT_EQ(rig.arm().counters().ignored_commands, 2U);
  EXPECT_FALSE(rig.arm().api_control());
  // 303 only drops control: what was queued before keeps running [I].
  rig.plain(C::START_API_CONTROL);
  rig.point(angular_position(target));
  rig.plain(C::STOP_API_CONTROL);
  rig.wait(500ms);
  EXPECT_EQ(rig.arm().joints()[0], static_cast<float>(target[0]));
  // NOINIT: points are refused even with API control; axes latch but do nothing.
  JacoRig cold{SimJacoConfig{}};
  cold.plain(C::START_API_CONTROL);
  cold.point(angular_position(target));
  cold.joystick(axes(0, 1.0F));
  cold.wait(500ms);
  EXPECT_EQ(cold.arm().fifo_size(), 0U);
  EXPECT_FALSE(cold.arm().last_motion_ns());
}

TEST(SimJaco, FingersMoveAtTheirSpeedAndAPointWaitsForThem) {
  JacoRig rig;  // JACO2: 0..6800, 3400 units/s
  rig.plain(C::START_API_CONTROL);
  jaco::TrajectoryPoint p = angular_position(rig.arm().joints());
  p.hand_mode = jaco::HandMode::POSITION;
  p.fingers = {3400.0F, 9000.0F, 0.0F};
  rig.point(p);
  rig.wait(500ms);
  EXPECT_NEAR(rig.arm().fingers()[0], 1700.0, 40.0);
  EXPECT_EQ(rig.arm().fifo_size(), 1U);
  rig.wait(1600ms);
  EXPECT_EQ(rig.arm().fingers()[0], 3400.0);
  EXPECT_EQ(rig.arm().fingers()[1], 6800.0);  // clamped to the model's range
  EXPECT_EQ(rig.arm().fifo_size(), 0U);
  EXPECT_FALSE(rig.arm().moving());  // joints did not move
}

TEST(SimJaco, CartesianPoseUpdatesOnlyInCartesianModeAndPointsGoThroughIk) {
  const SimJacoConfig c = ready_config();
  JacoRig rig(c);
  rig.plain(C::START_API_CONTROL);
  const jaco::NineFloats before = rig.nine(C::GET_CART_INFO);
  jaco::JointAngles moved = c.home_joints;
  moved[0] += 20.0;
  moved[2] += 10.0;
  rig.point(angular_position(moved));
  rig.wait(1s);
  EXPECT_EQ(rig.nine(C::GET_CART_INFO).values, before.values);  // angular mode: frozen
  rig.plain(C::SET_CONTROL_CARTESIAN);
  const auto truth =
      pose6(jaco::to_pose(jaco::forward_kinematics(rig.arm().joints(), jaco::jaco2_geometry())));
  const jaco::NineFloats now = rig.nine(C::GET_CART_INFO);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(now.values[i], truth[i], 1e-6);
  for (std::size_t i = 3; i < 6; ++i) EXPECT_NEAR(now.values[i], truth[i], 1e-6);
  // A Cartesian point: back to the pose of HOME.
  const auto home = pose6(jaco::to_pose(jaco::forward_kinematics(c.home_joints)));
  jaco::TrajectoryPoint p;
  for (std::size_t i = 0; i < 6; ++i) p.target[i] = static_cast<float>(home[i]);
  p.hand_mode = jaco::HandMode::NO_MOVEMENT;
  p.type = jaco::PositionType::CARTESIAN_POSITION;
  rig.point(p);
  EXPECT_NEAR(rig.nine(C::GET_CART_COMMAND).values[0], home[0], 1e-6);
  rig.wait(2s);
  EXPECT_EQ(rig.arm().fifo_size(), 0U);
  const jaco::NineFloats back = rig.nine(C::GET_CART_INFO);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(back.values[i], home[i], 1e-3);
  // The Cartesian joystick: axis 2 = up at 0.5 x 0.2 m/s.
  rig.joystick(axes(2, 0.5F));
  rig.wait(500ms);
  rig.joystick({});
  rig.wait(20ms);
  const jaco::NineFloats up = rig.nine(C::GET_CART_INFO);
  EXPECT_NEAR(up.values[2] - back.values[2], 0.05, 0.003);
  EXPECT_NEAR(up.values[0], back.values[0], 0.003);
  EXPECT_EQ(rig.arm().counters().ik_failures, 0U);
}

}  // namespace
}  // namespace orthoflow::simulation::test
