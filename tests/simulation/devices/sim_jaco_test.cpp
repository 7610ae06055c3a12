// The simulated JACO's behaviour (SimJacoArm behind SimJacoTransport), driven through the USB seam
// with packets from drivers/jaco/jaco_protocol.hpp: replies and slices, the HOME / RETRACT button
// and the firmware differences. The trajectory FIFO, velocity streams, the latched joystick, erase,
// API control, fingers and the Cartesian pose: sim_jaco_motion_test.cpp. The seam, faults, unplug
// and determinism: sim_jaco_transport_test.cpp.
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
