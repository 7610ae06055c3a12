// The simulated JACO's behaviour (SimJacoArm behind SimJacoTransport), driven through the USB seam
// with packets from drivers/jaco_protocol.hpp: replies and slices, the HOME / RETRACT button, the
// trajectory FIFO, velocity streams, the latched joystick, erase, API control, speed limits and
// the Cartesian pose. The seam, faults, unplug and determinism: sim_jaco_transport_test.cpp.
#include <algorithm>
#include <cmath>

#include "sim_jaco_test_support.hpp"

namespace orthoflow::simulation::test {
namespace {

using S = jaco::ArmState;
using C = jaco::Command;

TEST(SimJaco, EveryReplyEchoesTheCommandId) {
  JacoRig rig;
  for (const C c : {C::GET_CLIENT_INFO, C::GET_ANG_POS, C::GET_FIRMWARE, C::GET_ARM_STATUS,
                    C::GET_CART_INFO, C::GET_ANG_INFO, C::GET_CART_COMMAND, C::GET_ANG_COMMAND,
                    C::GET_CART_FORCE, C::GET_ANG_FORCE, C::GET_ANG_CURRENT, C::GET_SENSOR_INFO,
                    C::GET_ANG_CURRENT_MOTOR, C::GET_ANG_VEL, C::GET_ARM_INFO}) {
    const auto reply = rig.get(c);
    ASSERT_TRUE(reply) << jaco::to_string(c);
    EXPECT_EQ(jaco::check_reply(*reply, c), jaco::PacketCheck::OK) << jaco::to_string(c);
  }
  for (const C c : {C::START_API_CONTROL, C::SET_CONTROL_ANGULAR, C::SET_CONTROL_CARTESIAN,
                    C::START_FORCE_CONTROL, C::STOP_FORCE_CONTROL, C::ERASE_TRAJECTORIES,
                    C::STOP_API_CONTROL}) {
    const auto reply = rig.exchange(jaco::make_plain_command(c));
    ASSERT_TRUE(reply);
    EXPECT_EQ(jaco::read_header(*reply).command_id, static_cast<std::uint16_t>(c));
  }
  EXPECT_EQ(jaco::read_header(*rig.exchange(jaco::encode_joystick({}))).command_id, 305);
  EXPECT_EQ(jaco::read_header(*rig.exchange(jaco::encode_trajectory({}))).command_id, 308);
  // An unknown id (44 included) gets no reply: the IN waits its whole timeout.
  for (const std::uint16_t id : std::initializer_list<std::uint16_t>{44, 9999}) {
    ASSERT_TRUE(rig.write(jaco::make_packet({1, 1, id, 1})));
    jaco::Packet reply{};
    const std::int64_t t0 = rig.now();
    EXPECT_EQ(rig.read(reply).error().code, Code::TIMEOUT);
    EXPECT_EQ(rig.now() - t0, 1000 * MS);
  }
  EXPECT_EQ(rig.arm().counters().unknown_commands, 2U);
  // Replies carry the request's id_packet, the data's size, and the firmware and sensors set.
  jaco::Firmware fw;
  ASSERT_EQ(jaco::parse_firmware(*rig.get(C::GET_FIRMWARE), fw), jaco::PacketCheck::OK);
  EXPECT_EQ(fw.dsp.major, 5);
  EXPECT_EQ(fw.dsp.minor, 2);
  jaco::SensorInfo sensors;
  ASSERT_EQ(jaco::parse_sensor_info(*rig.get(C::GET_SENSOR_INFO), sensors), jaco::PacketCheck::OK);
  EXPECT_FLOAT_EQ(sensors.voltage_v, 24.0F);
  EXPECT_FLOAT_EQ(rig.nine(C::GET_ANG_CURRENT).values[1], 0.5F);
}

TEST(SimJaco, ClientInfoAndArmInfoComeInSlicesChosenByIdPacket) {
  SimJacoConfig c = ready_config();
  c.client_name = "left-arm";
  JacoRig rig(c);
  std::array<std::byte, 2 * jaco::BODY_BYTES> strings{};
  for (std::uint16_t i = 1; i <= 55; ++i) {
    const auto reply = rig.get(C::GET_CLIENT_INFO, i);
    ASSERT_TRUE(reply);
    EXPECT_EQ(jaco::read_header(*reply).id_packet, i);
    const auto body = std::span(*reply).subspan(jaco::HEADER_BYTES);
    if (i <= 2) {
      std::copy(body.begin(), body.end(), strings.begin() + (i - 1) * jaco::BODY_BYTES);
    } else {
      EXPECT_TRUE(std::all_of(body.begin(), body.end(),
                              [&](std::byte b) { return std::to_integer<std::uint16_t>(b) == i; }))
          << "slice " << i;
    }
  }
  jaco::ClientInfo info;
  ASSERT_EQ(jaco::parse_client_info(strings, info), jaco::PacketCheck::OK);
  EXPECT_EQ(info.name.view(), "left-arm");
  EXPECT_EQ(info.serial.view(), c.serial);
  EXPECT_EQ(info.model.view(), "JACO2 6DOF");
  EXPECT_EQ(jaco::detect_model(info, {}), jaco::Model::JACO2);
  // Out of range: a zero body. Arm info: slice 2 holds the state at body bytes 52-55.
  const auto none = rig.get(C::GET_CLIENT_INFO, 56);
  EXPECT_TRUE(
      std::all_of(none->begin() + 8, none->end(), [](std::byte b) { return b == std::byte{0}; }));
  jaco::ArmState state = S::ERROR;
  ASSERT_EQ(jaco::parse_arm_info_slice2(*rig.get(C::GET_ARM_INFO, 2), state),
            jaco::PacketCheck::OK);
  EXPECT_EQ(state, S::READY_STANDBY);
  EXPECT_EQ(jaco::body_u32(*rig.get(C::GET_ARM_INFO, 19), 0), 0x13131313U);
}

TEST(SimJaco, NoinitButtonPressHomesToReadyStandbyThenRelease) {
  const SimJacoConfig c;  // NOINIT at the retract pose
  JacoRig rig(c);
  EXPECT_EQ(rig.status_state(), S::NOINIT);
  rig.plain(C::START_API_CONTROL);
  const std::int64_t t0 = rig.now();
  rig.joystick(jaco::home_button_press());
  EXPECT_EQ(rig.status_state(), S::NORMAL_TO_READY);
  for (int polls = 0; polls < 500 && rig.status_state() != S::READY_STANDBY; ++polls) rig.wait(8ms);
  EXPECT_EQ(rig.arm().state(), S::READY_STANDBY);
  EXPECT_EQ(rig.arm().joints(), c.home_joints);
  // The slowest joint (2: 42.5 degrees at 36 deg/s) sets the time.
  const double seconds = static_cast<double>(rig.now() - t0) * 1e-9;
  EXPECT_GT(seconds, 42.5 / 36.0);
  EXPECT_LT(seconds, 42.5 / 36.0 + 0.05);
  rig.joystick({});
  rig.wait(1s);
  EXPECT_EQ(rig.status_state(), S::READY_STANDBY);
  EXPECT_FALSE(rig.arm().moving());
  EXPECT_EQ(rig.arm().joystick().buttons[jaco::HOME_BUTTON], 0);
}

TEST(SimJaco, PressAtHomeRetractsReleaseStopsAndTheNextPressReverses) {
  SimJacoConfig c = ready_config();
  c.held_home_to_retract_ns.reset();
  JacoRig rig(c);
  rig.plain(C::START_API_CONTROL);
  rig.joystick(jaco::home_button_press());
  EXPECT_EQ(rig.status_state(), S::READY_TO_RETRACT);
  rig.wait(300ms);
  rig.joystick({});
  const std::int64_t released = rig.now();
  rig.wait(20ms);
  EXPECT_FALSE(rig.arm().moving());
  EXPECT_LE(*rig.arm().last_motion_ns(), released + 10 * MS);
  const jaco::JointAngles stopped = rig.arm().joints();
  EXPECT_NE(stopped, c.home_joints);
  rig.wait(500ms);
  EXPECT_EQ(rig.arm().joints(), stopped);
  EXPECT_EQ(rig.status_state(), S::READY_TO_RETRACT);
  rig.joystick(jaco::home_button_press());  // reverses: back HOME
  EXPECT_EQ(rig.status_state(), S::RETRACT_TO_READY);
  rig.wait(2s);
  EXPECT_EQ(rig.status_state(), S::READY_STANDBY);
  EXPECT_EQ(rig.arm().joints(), c.home_joints);
  rig.joystick({});
  rig.joystick(jaco::home_button_press());
  rig.wait(2s);
  EXPECT_EQ(rig.status_state(), S::RETRACT_STANDBY);
  EXPECT_EQ(rig.arm().joints(), c.retract_joints);
  rig.joystick({});
  rig.joystick(jaco::home_button_press());
  EXPECT_EQ(rig.status_state(), S::RETRACT_TO_READY);
  // A repeated press packet is no new press: no reversal.
  rig.joystick(jaco::home_button_press());
  EXPECT_EQ(rig.status_state(), S::RETRACT_TO_READY);
}

TEST(SimJaco, HeldAtHomeTheArmGoesOnTowardRetract) {
  for (const bool flips : {true, false}) {
    SimJacoConfig c;
    c.start_state = S::NORMAL;
    c.held_home_to_retract_ns = flips ? std::optional<std::int64_t>(200 * MS) : std::nullopt;
    JacoRig rig(c);
    rig.plain(C::START_API_CONTROL);
    rig.joystick(jaco::home_button_press());
    rig.wait(1300ms);
    EXPECT_EQ(rig.status_state(), S::READY_STANDBY);
    rig.wait(300ms);
    EXPECT_EQ(rig.status_state(), flips ? S::READY_TO_RETRACT : S::READY_STANDBY);
  }
  SimJacoConfig stuck;
  stuck.faults.never_leave_noinit = true;
  JacoRig rig(stuck);
  rig.plain(C::START_API_CONTROL);
  rig.joystick(jaco::home_button_press());
  rig.wait(2s);
  EXPECT_EQ(rig.status_state(), S::NOINIT);
  EXPECT_FALSE(rig.arm().last_motion_ns());
}

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

TEST(SimJaco, DspBelow5AnswersPositionsOnVelocityAndHasNoStatusCommand) {
  const SimJacoConfig v1 = sim_jaco_v1_config();
  JacoRig rig(v1);
  const jaco::NineFloats vel = rig.nine(C::GET_ANG_VEL);
  EXPECT_EQ(vel.values[1], static_cast<float>(v1.retract_joints[1]));
  ASSERT_TRUE(rig.write(jaco::make_request(C::GET_ARM_STATUS)));
  jaco::Packet reply{};
  EXPECT_EQ(rig.read(reply).error().code, Code::TIMEOUT);
  jaco::ArmState state = S::ERROR;
  ASSERT_EQ(jaco::parse_arm_info_slice2(*rig.get(C::GET_ARM_INFO, 2), state),
            jaco::PacketCheck::OK);
  EXPECT_EQ(state, S::NOINIT);
  EXPECT_EQ(rig.arm().finger_max(), 60.0);
  // DSP >= 5 answers velocities on 114.
  JacoRig j2;
  j2.plain(C::START_API_CONTROL);
  j2.joystick(axes(0, 0.5F));
  j2.wait(50ms);
  EXPECT_NEAR(j2.nine(C::GET_ANG_VEL).values[0], 18.0F, 1e-4);
}

}  // namespace
}  // namespace orthoflow::simulation::test
