// The Kinova JACO's USB packet codec as pure functions (JACO.md 3-7, 10.1): every packet layout
// byte for byte, encode/decode round trips, reply validation, the refusals of untrusted bytes
// (short packets, wrong ids, NaN / Inf, bad enumerations, bad strings), model detection and the
// HOME / RETRACT virtual-button table, checked row by row and then driven against a small model of
// the arm's button behaviour.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "drivers/jaco/jaco_protocol.hpp"

namespace orthoflow::drivers::jaco {
namespace {

constexpr float NaN = std::numeric_limits<float>::quiet_NaN();
constexpr float INF = std::numeric_limits<float>::infinity();

// Hand-written little-endian accessors, independent of the codec under test.
std::size_t body(std::size_t byte) { return HEADER_BYTES + byte; }
std::uint16_t u16_at(const Packet& p, std::size_t off) {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(p[off]) |
                                    std::to_integer<unsigned>(p[off + 1]) << 8U);
}
std::uint32_t u32_at(const Packet& p, std::size_t off) {
  std::uint32_t v = 0;
  for (unsigned i = 0; i < 4; ++i) v |= std::to_integer<std::uint32_t>(p[off + i]) << (8U * i);
  return v;
}
void put_u16(Packet& p, std::size_t off, std::uint16_t v) {
  p[off] = static_cast<std::byte>(v & 0xFFU);
  p[off + 1] = static_cast<std::byte>(v >> 8U);
}
void put_u32(Packet& p, std::size_t off, std::uint32_t v) {
  for (unsigned i = 0; i < 4; ++i) p[off + i] = static_cast<std::byte>((v >> (8U * i)) & 0xFFU);
}
void put_f32(Packet& p, std::size_t off, float v) {
  put_u32(p, off, std::bit_cast<std::uint32_t>(v));
}
Packet header_only(std::uint16_t id, std::uint16_t quantity, std::uint16_t command,
                   std::uint16_t size) {
  Packet p{};
  put_u16(p, 0, id);
  put_u16(p, 2, quantity);
  put_u16(p, 4, command);
  put_u16(p, 6, size);
  return p;
}
bool body_zero_from(const Packet& p, std::size_t body_byte) {
  for (std::size_t i = body(body_byte); i < PACKET_BYTES; ++i) {
    if (p[i] != std::byte{0}) return false;
  }
  return true;
}
template <std::size_t N>
bool same_bits(const std::array<float, N>& a, const std::array<float, N>& b) {
  return std::memcmp(a.data(), b.data(), sizeof(float) * N) == 0;
}

struct NamedCommand {
  Command command;
  std::uint16_t id;
  const char* name;
};
const std::vector<NamedCommand>& all_commands() {
  static const std::vector<NamedCommand> list = {
      {Command::GET_CLIENT_INFO, 1, "get_client_info"},
      {Command::GET_ANG_POS, 15, "get_ang_pos"},
      {Command::GET_FIRMWARE, 36, "get_firmware"},
      {Command::SET_CONTROL_ANGULAR, 47, "set_control_angular"},
      {Command::SET_CONTROL_CARTESIAN, 49, "set_control_cartesian"},
      {Command::START_FORCE_CONTROL, 57, "start_force_control"},
      {Command::STOP_FORCE_CONTROL, 58, "stop_force_control"},
      {Command::GET_ARM_STATUS, 62, "get_arm_status"},
      {Command::GET_CART_INFO, 104, "get_cart_info"},
      {Command::GET_ANG_INFO, 105, "get_ang_info"},
      {Command::GET_CART_COMMAND, 106, "get_cart_command"},
      {Command::GET_ANG_COMMAND, 107, "get_ang_command"},
      {Command::GET_CART_FORCE, 108, "get_cart_force"},
      {Command::GET_ANG_FORCE, 109, "get_ang_force"},
      {Command::GET_ANG_CURRENT, 110, "get_ang_current"},
      {Command::GET_SENSOR_INFO, 111, "get_sensor_info"},
      {Command::GET_ANG_CURRENT_MOTOR, 113, "get_ang_current_motor"},
      {Command::GET_ANG_VEL, 114, "get_ang_vel"},
      {Command::GET_ARM_INFO, 200, "get_arm_info"},
      {Command::ERASE_TRAJECTORIES, 301, "erase_trajectories"},
      {Command::START_API_CONTROL, 302, "start_api_control"},
      {Command::STOP_API_CONTROL, 303, "stop_api_control"},
      {Command::JOYSTICK, 305, "joystick"},
      {Command::SEND_BASIC_TRAJECTORY, 308, "send_basic_trajectory"},
  };
  return list;
}

const std::vector<ArmState>& all_states() {
  static const std::vector<ArmState> list = {ArmState::NORMAL_TO_READY,  ArmState::READY_STANDBY,
                                             ArmState::READY_TO_RETRACT, ArmState::RETRACT_STANDBY,
                                             ArmState::RETRACT_TO_READY, ArmState::NORMAL,
                                             ArmState::NOINIT,           ArmState::ERROR};
  return list;
}

// ---- header and plain packets (JACO.md 3) -----------------------------------------------------

TEST(JacoProtocol, HeaderIsFourLittleEndianU16AndTheBodyIsZero) {
  const Packet p = make_packet({0x0102, 0x0304, 0x0506, 0x0708});
  const std::array<int, 8> want = {0x02, 0x01, 0x04, 0x03, 0x06, 0x05, 0x08, 0x07};
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(std::to_integer<int>(p[i]), want[i]) << "byte " << i;
  }
  EXPECT_TRUE(body_zero_from(p, 0));
  const PacketHeader h = read_header(p);
  EXPECT_EQ(h.id_packet, 0x0102);
  EXPECT_EQ(h.packet_quantity, 0x0304);
  EXPECT_EQ(h.command_id, 0x0506);
  EXPECT_EQ(h.command_size, 0x0708);
  const PacketHeader extremes{0xFFFF, 0, 0x8001, 0xFF00};
  const PacketHeader back = read_header(make_packet(extremes));
  EXPECT_EQ(back.id_packet, 0xFFFF);
  EXPECT_EQ(back.packet_quantity, 0);
  EXPECT_EQ(back.command_id, 0x8001);
  EXPECT_EQ(back.command_size, 0xFF00);
}

TEST(JacoProtocol, RequestsCarryTheSliceIndexQuantityOneAndCommandSizeOne) {
  for (const auto& c : all_commands()) {
    EXPECT_EQ(make_request(c.command), header_only(1, 1, c.id, 1)) << c.name;
  }
  // Multi-packet reads: request i carries id_packet = i, packet_quantity stays 1 (JACO.md 4).
  for (std::uint16_t i = 1; i <= CLIENT_INFO_SLICES; ++i) {
    EXPECT_EQ(make_request(Command::GET_CLIENT_INFO, i), header_only(i, 1, 1, 1)) << i;
  }
  EXPECT_EQ(make_request(Command::GET_ARM_INFO, 2), header_only(2, 1, 200, 1));
}

TEST(JacoProtocol, PlainCommandsHaveSizeZeroExceptSetCartesianWhichHasOne) {
  const std::vector<std::pair<Command, std::uint16_t>> sizes = {
      {Command::SET_CONTROL_ANGULAR, 0}, {Command::SET_CONTROL_CARTESIAN, 1},
      {Command::START_FORCE_CONTROL, 0}, {Command::STOP_FORCE_CONTROL, 0},
      {Command::ERASE_TRAJECTORIES, 0},  {Command::START_API_CONTROL, 0},
      {Command::STOP_API_CONTROL, 0}};
  for (const auto& [command, size] : sizes) {
    EXPECT_EQ(make_plain_command(command),
              header_only(1, 1, static_cast<std::uint16_t>(command), size))
        << to_string(command);
  }
}

TEST(JacoProtocol, BodyAccessorsAreLittleEndianAtBodyOffsets) {
  Packet p{};
  set_body_float(p, 0, 1.0F);  // 0x3F800000
  EXPECT_EQ(u32_at(p, 8), 0x3F800000U);
  set_body_float(p, BODY_FLOATS - 1, -2.5F);
  EXPECT_EQ(u32_at(p, 60), std::bit_cast<std::uint32_t>(-2.5F));
  EXPECT_EQ(body_float(p, 13), -2.5F);
  set_body_u32(p, 4, 0x11223344U);
  EXPECT_EQ(std::to_integer<int>(p[12]), 0x44);
  EXPECT_EQ(std::to_integer<int>(p[15]), 0x11);
  EXPECT_EQ(body_u32(p, 4), 0x11223344U);
  set_body_i32(p, 52, -2);
  EXPECT_EQ(u32_at(p, 60), 0xFFFFFFFEU);
  EXPECT_EQ(body_i32(p, 52), -2);
  // The header is untouched by body writes.
  for (std::size_t i = 0; i < HEADER_BYTES; ++i) EXPECT_EQ(p[i], std::byte{0});
}

// ---- reply validation (JACO.md 4) ---------------------------------------------------------------

TEST(JacoProtocol, CheckReplyWantsAllSixtyFourBytesAndTheSameCommandId) {
  const Packet ok = make_request(Command::GET_ANG_POS);
  const std::span<const std::byte> bytes(ok);
  EXPECT_EQ(check_reply({}, Command::GET_ANG_POS), PacketCheck::SHORT);
  EXPECT_EQ(check_reply(bytes.first(1), Command::GET_ANG_POS), PacketCheck::SHORT);
  EXPECT_EQ(check_reply(bytes.first(63), Command::GET_ANG_POS), PacketCheck::SHORT);
  EXPECT_EQ(check_reply(bytes, Command::GET_ANG_POS), PacketCheck::OK);
  // Short is checked first: 63 bytes with the wrong id is SHORT.
  EXPECT_EQ(check_reply(bytes.first(63), Command::GET_CART_INFO), PacketCheck::SHORT);
  EXPECT_EQ(check_reply(bytes, Command::GET_CART_INFO), PacketCheck::WRONG_COMMAND);
  // 64 bytes or more: only the first packet's command id counts.
  std::vector<std::byte> longer(ok.begin(), ok.end());
  longer.resize(200, std::byte{0xEE});
  EXPECT_EQ(check_reply(longer, Command::GET_ANG_POS), PacketCheck::OK);
  EXPECT_EQ(check_reply(std::span(longer).first(65), Command::GET_ANG_POS), PacketCheck::OK);
  // Nothing else in the header is checked (JACO.md 4: its contents in replies are unknown).
  Packet odd = ok;
  put_u16(odd, 0, 0xFFFF);
  put_u16(odd, 2, 0);
  put_u16(odd, 6, 0xABCD);
  EXPECT_EQ(check_reply(odd, Command::GET_ANG_POS), PacketCheck::OK);
  // Both bytes of the id are compared.
  for (const auto& c : all_commands()) {
    const Packet reply = make_request(c.command);
    for (const auto& other : all_commands()) {
      EXPECT_EQ(check_reply(reply, other.command),
                c.id == other.id ? PacketCheck::OK : PacketCheck::WRONG_COMMAND)
          << c.name << " vs " << other.name;
    }
    Packet high = reply;
    put_u16(high, 4, static_cast<std::uint16_t>(c.id | 0x0400U));
    EXPECT_EQ(check_reply(high, c.command), PacketCheck::WRONG_COMMAND) << c.name;
  }
}

// ---- trajectory point (JACO.md 6.1) -------------------------------------------------------------

TrajectoryPoint sample_point() {
  TrajectoryPoint p;
  p.target = {10.5F, -20.25F, 30.0F, 275.0F, -0.125F, 440.0F};
  p.fingers = {0.25F, 50.0F, 6400.0F};
  p.delay_s = 1.5F;
  p.hand_mode = HandMode::VELOCITY;
  p.type = PositionType::TIME_DELAY;
  return p;
}

TEST(JacoProtocol, TrajectoryPointIsTheFortyEightByteLayout) {
  const TrajectoryPoint point = sample_point();
  Packet want = header_only(1, 1, 308, 48);
  for (std::size_t i = 0; i < 6; ++i) put_f32(want, body(4 * i), point.target[i]);
  for (std::size_t i = 0; i < 3; ++i) put_f32(want, body(24 + 4 * i), point.fingers[i]);
  put_f32(want, body(36), 1.5F);
  put_u32(want, body(40), 2);   // hand mode velocity
  put_u32(want, body(44), 12);  // time delay
  const Packet got = encode_trajectory(point);
  EXPECT_EQ(got, want);
  EXPECT_TRUE(body_zero_from(got, 48));
  // libkindrv's set_target_ang: angular position, hand mode 1, delay 0.
  TrajectoryPoint ang;
  ang.target = {1, 2, 3, 4, 5, 6};
  const Packet a = encode_trajectory(ang);
  EXPECT_EQ(u32_at(a, body(36)), 0U);
  EXPECT_EQ(u32_at(a, body(40)), 1U);
  EXPECT_EQ(u32_at(a, body(44)), 2U);
}

TEST(JacoProtocol, TrajectoryRoundTripsEveryTypeAndHandMode) {
  for (const PositionType type : {PositionType::NO_MOVEMENT, PositionType::CARTESIAN_POSITION,
                                  PositionType::ANGULAR_POSITION, PositionType::CARTESIAN_VELOCITY,
                                  PositionType::ANGULAR_VELOCITY, PositionType::TIME_DELAY}) {
    for (const HandMode hand : {HandMode::NO_MOVEMENT, HandMode::POSITION, HandMode::VELOCITY}) {
      TrajectoryPoint in = sample_point();
      in.type = type;
      in.hand_mode = hand;
      in.target[0] = -0.0F;
      in.fingers[2] = std::numeric_limits<float>::denorm_min();
      in.delay_s = std::numeric_limits<float>::max();
      TrajectoryPoint out;
      ASSERT_EQ(decode_trajectory(encode_trajectory(in), out), PacketCheck::OK);
      EXPECT_TRUE(same_bits(out.target, in.target));
      EXPECT_TRUE(same_bits(out.fingers, in.fingers));
      EXPECT_EQ(std::bit_cast<std::uint32_t>(out.delay_s),
                std::bit_cast<std::uint32_t>(in.delay_s));
      EXPECT_EQ(out.hand_mode, hand);
      EXPECT_EQ(out.type, type);
    }
  }
}

TEST(JacoProtocol, TrajectoryRefusesNaNOrInfInEachOfItsTenFloats) {
  const Packet good = encode_trajectory(sample_point());
  for (std::size_t pos = 0; pos < 10; ++pos) {
    for (const float bad : {NaN, INF, -INF, -NaN}) {
      Packet p = good;
      set_body_float(p, pos, bad);
      TrajectoryPoint out;
      out.delay_s = 99.0F;
      EXPECT_EQ(decode_trajectory(p, out), PacketCheck::NOT_FINITE) << "float " << pos;
      EXPECT_EQ(out.delay_s, 99.0F) << "out untouched on refusal";
    }
    Packet signalling = good;
    put_u32(signalling, body(4 * pos), 0x7F800001U);
    TrajectoryPoint out;
    EXPECT_EQ(decode_trajectory(signalling, out), PacketCheck::NOT_FINITE) << "sNaN " << pos;
  }
  // A NaN in the zero tail (body 48-55, not a field) is not looked at.
  Packet tail = good;
  set_body_float(tail, 12, NaN);
  TrajectoryPoint out;
  EXPECT_EQ(decode_trajectory(tail, out), PacketCheck::OK);
}

TEST(JacoProtocol, TrajectoryRefusesUnknownHandModesAndTypes) {
  const Packet good = encode_trajectory(sample_point());
  for (const std::int32_t hand : {3, 4, 6, -1, 1000, std::numeric_limits<std::int32_t>::min()}) {
    Packet p = good;
    set_body_i32(p, 40, hand);
    TrajectoryPoint out;
    out.delay_s = 99.0F;
    EXPECT_EQ(decode_trajectory(p, out), PacketCheck::BAD_VALUE) << "hand " << hand;
    EXPECT_EQ(out.delay_s, 99.0F);
  }
  // 3-6 and 9-11 exist in the SDK only; this codec speaks libkindrv's basic trajectory.
  for (const std::int32_t type : {3, 4, 5, 6, 9, 10, 11, 13, -1, 25000}) {
    Packet p = good;
    set_body_i32(p, 44, type);
    TrajectoryPoint out;
    EXPECT_EQ(decode_trajectory(p, out), PacketCheck::BAD_VALUE) << "type " << type;
  }
  for (const std::int32_t type : {0, 1, 2, 7, 8, 12}) {
    Packet p = good;
    set_body_i32(p, 44, type);
    TrajectoryPoint out;
    EXPECT_EQ(decode_trajectory(p, out), PacketCheck::OK) << "type " << type;
    EXPECT_EQ(static_cast<std::int32_t>(out.type), type);
  }
}

// ---- joystick (JACO.md 6.2) ---------------------------------------------------------------------

TEST(JacoProtocol, JoystickIsSixteenButtonsThenSixAxesAtBody32) {
  JoystickState s;
  for (std::size_t i = 0; i < 16; ++i) s.buttons[i] = static_cast<std::uint16_t>(i % 3 == 0);
  s.axes = {0.5F, -1.0F, 0.25F, 1.0F, -0.75F, 0.125F};
  Packet want = header_only(1, 1, 305, 56);
  for (std::size_t i = 0; i < 16; ++i) put_u16(want, body(2 * i), s.buttons[i]);
  for (std::size_t i = 0; i < 6; ++i) put_f32(want, body(32 + 4 * i), s.axes[i]);
  EXPECT_EQ(encode_joystick(s), want);
  EXPECT_FALSE(s.is_release());
}

TEST(JacoProtocol, ReleaseIsAnAllZeroBodyAndHomePressIsButtonTwo) {
  const JoystickState release;
  EXPECT_TRUE(release.is_release());
  const Packet r = encode_joystick(release);
  EXPECT_EQ(r, header_only(1, 1, 305, 56));
  EXPECT_TRUE(body_zero_from(r, 0));

  const JoystickState press = home_button_press();
  EXPECT_FALSE(press.is_release());
  for (std::size_t i = 0; i < 16; ++i) EXPECT_EQ(press.buttons[i], i == HOME_BUTTON ? 1 : 0);
  Packet want = header_only(1, 1, 305, 56);
  put_u16(want, body(4), 1);
  EXPECT_EQ(encode_joystick(press), want);
  EXPECT_EQ(u16_at(encode_joystick(press), body(2 * HOME_BUTTON)), 1);

  JoystickState axis_only;
  axis_only.axes[5] = 0.01F;
  EXPECT_FALSE(axis_only.is_release());
  JoystickState button_only;
  button_only.buttons[15] = 1;
  EXPECT_FALSE(button_only.is_release());
}

TEST(JacoProtocol, JoystickRoundTripsAndRefusesBadButtonsAndAxes) {
  JoystickState in;
  in.buttons[0] = 1;
  in.buttons[HOME_BUTTON] = 1;
  in.buttons[15] = 1;
  in.axes = {-1.0F, 1.0F, 0.0F, 2.5F, -2.5F, std::numeric_limits<float>::denorm_min()};
  JoystickState out;
  ASSERT_EQ(decode_joystick(encode_joystick(in), out), PacketCheck::OK);
  EXPECT_EQ(out.buttons, in.buttons);
  EXPECT_TRUE(same_bits(out.axes, in.axes));
  ASSERT_EQ(decode_joystick(encode_joystick(JoystickState{}), out), PacketCheck::OK);
  EXPECT_TRUE(out.is_release());

  const Packet good = encode_joystick(in);
  for (std::size_t b = 0; b < 16; ++b) {
    for (const std::uint16_t bad :
         {std::uint16_t{2}, std::uint16_t{0x0100}, std::uint16_t{0xFFFF}}) {
      Packet p = good;
      put_u16(p, body(2 * b), bad);
      JoystickState o = in;
      o.axes[0] = 42.0F;
      EXPECT_EQ(decode_joystick(p, o), PacketCheck::BAD_VALUE) << "button " << b;
      EXPECT_EQ(o.axes[0], 42.0F) << "out untouched on refusal";
    }
  }
  for (std::size_t a = 0; a < 6; ++a) {
    for (const float bad : {NaN, INF, -INF}) {
      Packet p = good;
      set_body_float(p, 8 + a, bad);
      JoystickState o;
      o.axes[0] = 42.0F;
      EXPECT_EQ(decode_joystick(p, o), PacketCheck::NOT_FINITE) << "axis " << a;
      EXPECT_EQ(o.axes[0], 42.0F);
    }
  }
}

// ---- nine-float replies (JACO.md 5) -------------------------------------------------------------

NineFloats sample_nine() {
  NineFloats n;
  n.values = {0.5F, -1.25F, 270.0F, 440.0F, -0.0F, 3.14159F};
  n.fingers = {0.25F, 57.0F, 6800.0F};
  return n;
}

TEST(JacoProtocol, NineFloatsLayoutAndRoundTripForEveryReplyCommand) {
  const NineFloats in = sample_nine();
  for (const Command c : {Command::GET_ANG_POS, Command::GET_CART_INFO, Command::GET_ANG_INFO,
                          Command::GET_CART_COMMAND, Command::GET_ANG_COMMAND,
                          Command::GET_CART_FORCE, Command::GET_ANG_FORCE, Command::GET_ANG_CURRENT,
                          Command::GET_ANG_CURRENT_MOTOR, Command::GET_ANG_VEL}) {
    const Packet p = encode_nine(c, in);
    EXPECT_EQ(read_header(p).command_id, static_cast<std::uint16_t>(c));
    EXPECT_EQ(check_reply(p, c), PacketCheck::OK) << to_string(c);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_EQ(u32_at(p, body(4 * i)), std::bit_cast<std::uint32_t>(in.values[i]));
    }
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(u32_at(p, body(24 + 4 * i)), std::bit_cast<std::uint32_t>(in.fingers[i]));
    }
    EXPECT_TRUE(body_zero_from(p, 36));
    NineFloats out;
    ASSERT_EQ(parse_nine(p, out), PacketCheck::OK);
    EXPECT_TRUE(same_bits(out.values, in.values));
    EXPECT_TRUE(same_bits(out.fingers, in.fingers));
  }
}

TEST(JacoProtocol, NineFloatsRefuseNaNOrInfInEachPositionAndIgnoreTheRest) {
  const Packet good = encode_nine(Command::GET_ANG_POS, sample_nine());
  for (std::size_t pos = 0; pos < 9; ++pos) {
    for (const float bad : {NaN, INF, -INF}) {
      Packet p = good;
      set_body_float(p, pos, bad);
      NineFloats out;
      out.values[0] = 42.0F;
      EXPECT_EQ(parse_nine(p, out), PacketCheck::NOT_FINITE) << "float " << pos;
      EXPECT_EQ(out.values[0], 42.0F) << "out untouched on refusal";
    }
  }
  // Floats 9-13 are not part of these replies.
  Packet p = good;
  for (std::size_t pos = 9; pos < BODY_FLOATS; ++pos) set_body_float(p, pos, NaN);
  NineFloats out;
  EXPECT_EQ(parse_nine(p, out), PacketCheck::OK);
}

// ---- sensor info (JACO.md 6.3) ------------------------------------------------------------------

SensorInfo sample_sensors() {
  SensorInfo s;
  s.voltage_v = 24.1F;
  s.current_a = 0.6F;
  s.accel_g = {0.01F, -0.02F, 0.99F};
  s.actuator_temp_c = {30.0F, 31.0F, 32.0F, 33.0F, 34.0F, 35.0F};
  s.finger_temp_c = {25.0F, 26.0F, 27.0F};
  return s;
}

TEST(JacoProtocol, SensorInfoFillsTheFourteenFloatsInOrderAndRoundTrips) {
  const SensorInfo in = sample_sensors();
  const Packet p = encode_sensor_info(in);
  EXPECT_EQ(read_header(p).command_id, 111);
  EXPECT_EQ(read_header(p).command_size, 56);
  const std::array<float, 14> order = {24.1F, 0.6F,  0.01F, -0.02F, 0.99F, 30.0F, 31.0F,
                                       32.0F, 33.0F, 34.0F, 35.0F,  25.0F, 26.0F, 27.0F};
  for (std::size_t i = 0; i < 14; ++i) {
    EXPECT_EQ(u32_at(p, body(4 * i)), std::bit_cast<std::uint32_t>(order[i])) << i;
  }
  SensorInfo out;
  ASSERT_EQ(parse_sensor_info(p, out), PacketCheck::OK);
  EXPECT_EQ(out.voltage_v, in.voltage_v);
  EXPECT_EQ(out.current_a, in.current_a);
  EXPECT_EQ(out.accel_g, in.accel_g);
  EXPECT_EQ(out.actuator_temp_c, in.actuator_temp_c);
  EXPECT_EQ(out.finger_temp_c, in.finger_temp_c);
}

TEST(JacoProtocol, SensorInfoRefusesNaNOrInfInEachOfTheFourteenFloats) {
  const Packet good = encode_sensor_info(sample_sensors());
  for (std::size_t pos = 0; pos < BODY_FLOATS; ++pos) {
    for (const float bad : {NaN, INF, -INF}) {
      Packet p = good;
      set_body_float(p, pos, bad);
      SensorInfo out;
      out.voltage_v = 42.0F;
      EXPECT_EQ(parse_sensor_info(p, out), PacketCheck::NOT_FINITE) << "float " << pos;
      EXPECT_EQ(out.voltage_v, 42.0F);
    }
  }
}

// ---- client info (JACO.md 6.4) ------------------------------------------------------------------

using Slices = std::array<std::byte, 2 * BODY_BYTES>;

Slices client_slices(const std::array<std::string, 5>& fields) {
  Slices s{};
  for (std::size_t f = 0; f < 5; ++f) {
    std::memcpy(s.data() + f * CLIENT_STRING_BYTES, fields[f].data(), fields[f].size());
  }
  return s;
}

TEST(JacoProtocol, ClientInfoIsFiveNulTerminatedTwentyByteStrings) {
  const Slices s =
      client_slices({"CID-7", "JacoArm", "Fawkes", "PJ00900006161250001", "JACO2 6DOF"});
  ClientInfo info;
  ASSERT_EQ(parse_client_info(s, info), PacketCheck::OK);
  EXPECT_EQ(info.client_id.view(), "CID-7");
  EXPECT_EQ(info.name.view(), "JacoArm");
  EXPECT_EQ(info.organisation.view(), "Fawkes");
  EXPECT_EQ(info.serial.view(), "PJ00900006161250001");  // 19 bytes: the longest that fits
  EXPECT_EQ(info.model.view(), "JACO2 6DOF");

  Slices round{};
  encode_client_info(info, round);
  EXPECT_EQ(round, s);
  ClientInfo again;
  ASSERT_EQ(parse_client_info(round, again), PacketCheck::OK);
  EXPECT_EQ(again.serial, info.serial);
  EXPECT_EQ(again.model, info.model);
}

TEST(JacoProtocol, ClientInfoAcceptsEmptyStringsAndIgnoresPaddingAndTheTail) {
  ClientInfo info;
  info.name.assign("stale");
  ASSERT_EQ(parse_client_info(Slices{}, info), PacketCheck::OK);
  EXPECT_TRUE(info.client_id.empty());
  EXPECT_TRUE(info.name.empty());
  EXPECT_TRUE(info.model.empty());
  // Bytes after a string's NUL and the 12 undecoded bytes (100-111) are not read.
  Slices s = client_slices({"a", "b", "c", "d", "e"});
  s[5] = std::byte{0xFF};
  s[20 + 19] = std::byte{0x01};
  for (std::size_t i = 100; i < s.size(); ++i) s[i] = std::byte{0x80};
  ASSERT_EQ(parse_client_info(s, info), PacketCheck::OK);
  EXPECT_EQ(info.client_id.view(), "a");
  EXPECT_EQ(info.model.view(), "e");
  // encode truncates to 19 bytes so the NUL always fits.
  ClientInfo longest;
  longest.name.assign("ABCDEFGHIJKLMNOPQRST");  // 20
  Slices out{};
  encode_client_info(longest, out);
  ClientInfo back;
  ASSERT_EQ(parse_client_info(out, back), PacketCheck::OK);
  EXPECT_EQ(back.name.view(), "ABCDEFGHIJKLMNOPQRS");
}

TEST(JacoProtocol, ClientInfoRefusesAMissingNulOrANonPrintableByteInEachString) {
  for (std::size_t f = 0; f < 5; ++f) {
    Slices s = client_slices({"id", "name", "org", "serial", "model"});
    std::memset(s.data() + f * CLIENT_STRING_BYTES, 'X', CLIENT_STRING_BYTES);  // 20, no NUL
    ClientInfo info;
    info.name.assign("kept");
    EXPECT_EQ(parse_client_info(s, info), PacketCheck::BAD_STRING) << "field " << f;
    EXPECT_EQ(info.name.view(), "kept") << "out untouched on refusal";
    for (const int bad : {0x01, 0x09, 0x1F, 0x7F, 0x80, 0xFF}) {
      Slices t = client_slices({"id", "name", "org", "serial", "model"});
      t[f * CLIENT_STRING_BYTES + 1] = static_cast<std::byte>(bad);
      EXPECT_EQ(parse_client_info(t, info), PacketCheck::BAD_STRING)
          << "field " << f << " byte " << bad;
    }
  }
  // The printable edges are accepted.
  ClientInfo info;
  EXPECT_EQ(parse_client_info(client_slices({" ~", "", "", "", ""}), info), PacketCheck::OK);
  EXPECT_EQ(info.client_id.view(), " ~");
}

// ---- firmware (JACO.md 6.5) ---------------------------------------------------------------------

TEST(JacoProtocol, FirmwareWordsAreMajorMinorPatchBytes) {
  const FirmwareVersion v = firmware_word(0x00050A03U);
  EXPECT_EQ(v.major, 5);
  EXPECT_EQ(v.minor, 10);
  EXPECT_EQ(v.patch, 3);
  const FirmwareVersion top = firmware_word(0xFF040201U);  // the top byte is not part of it
  EXPECT_EQ(top.major, 4);
  EXPECT_EQ(top.minor, 2);
  EXPECT_EQ(top.patch, 1);
  EXPECT_FALSE(firmware_word(0x00040000U).dsp5());
  EXPECT_TRUE(firmware_word(0x00050000U).dsp5());
  EXPECT_TRUE(firmware_word(0x00060102U).dsp5());
  EXPECT_FALSE(FirmwareVersion{}.dsp5());
}

TEST(JacoProtocol, FirmwareReplyLayoutRoundTripAndMajorZeroRefused) {
  Packet p = header_only(1, 1, 36, 52);
  put_u32(p, body(0), 0x00050201U);
  for (std::size_t i = 0; i < 6; ++i)
    put_u32(p, body(4 + 4 * i), 0x00010000U + static_cast<std::uint32_t>(i));
  for (std::size_t i = 0; i < 3; ++i)
    put_u32(p, body(28 + 4 * i), 0x00020300U + static_cast<std::uint32_t>(i));
  put_u32(p, body(40), 7);            // DSP iteration: not decoded
  put_u32(p, body(44), 0xFFFFFFFFU);  // CAN interfaces: not decoded
  Firmware fw;
  ASSERT_EQ(parse_firmware(p, fw), PacketCheck::OK);
  EXPECT_EQ(fw.dsp.major, 5);
  EXPECT_EQ(fw.dsp.minor, 2);
  EXPECT_EQ(fw.dsp.patch, 1);
  EXPECT_TRUE(fw.dsp.dsp5());
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(fw.actuators[i].major, 1);
    EXPECT_EQ(fw.actuators[i].patch, i);
  }
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(fw.fingers[i].major, 2);
    EXPECT_EQ(fw.fingers[i].minor, 3);
    EXPECT_EQ(fw.fingers[i].patch, i);
  }
  const Packet enc = encode_firmware(fw);
  EXPECT_EQ(read_header(enc).command_size, 52);
  for (std::size_t w = 0; w < 10; ++w) EXPECT_EQ(u32_at(enc, body(4 * w)), u32_at(p, body(4 * w)));
  Firmware again;
  ASSERT_EQ(parse_firmware(enc, again), PacketCheck::OK);
  EXPECT_EQ(again.dsp.major, 5);
  EXPECT_EQ(again.fingers[2].patch, 2);

  Packet zero = p;
  put_u32(zero, body(0), 0x00000901U);  // major 0
  Firmware kept;
  kept.dsp.major = 9;
  EXPECT_EQ(parse_firmware(zero, kept), PacketCheck::BAD_VALUE);
  EXPECT_EQ(kept.dsp.major, 9) << "out untouched on refusal";
  EXPECT_EQ(parse_firmware(Packet{}, kept), PacketCheck::BAD_VALUE);
}

// ---- arm status and arm info (JACO.md 6.6, 7.3) -------------------------------------------------

TEST(JacoProtocol, ArmStatusBytesZeroOneTwoFourSixTenElevenFourteen) {
  Packet p = header_only(1, 1, 62, 16);
  for (std::size_t i = 0; i < BODY_BYTES; ++i) p[body(i)] = std::byte{0xAA};  // not fields
  p[body(0)] = std::byte{1};
  p[body(1)] = std::byte{0};
  p[body(2)] = std::byte{7};
  p[body(4)] = std::byte{3};
  p[body(6)] = std::byte{1};
  p[body(10)] = std::byte{2};
  p[body(11)] = std::byte{0};
  p[body(14)] = std::byte{5};
  ArmStatus s;
  ASSERT_EQ(parse_arm_status(p, s), PacketCheck::OK);
  EXPECT_EQ(s.finger_init, (std::array<std::uint8_t, 3>{1, 0, 7}));
  EXPECT_EQ(s.state, ArmState::RETRACT_STANDBY);
  EXPECT_EQ(s.api_control, 1);
  EXPECT_EQ(s.force_control, 2);
  EXPECT_EQ(s.current_limitation, 0);
  EXPECT_EQ(s.torque_sensors, 5);

  Packet want = header_only(1, 1, 62, 16);
  for (const auto& [i, v] : std::vector<std::pair<std::size_t, int>>{
           {0, 1}, {1, 0}, {2, 7}, {4, 3}, {6, 1}, {10, 2}, {11, 0}, {14, 5}}) {
    want[body(i)] = static_cast<std::byte>(v);
  }
  EXPECT_EQ(encode_arm_status(s), want);
}

TEST(JacoProtocol, ArmStatusRoundTripsStatesZeroToSixAndRefusesOtherBytes) {
  for (std::int32_t raw = 0; raw <= 6; ++raw) {
    ArmStatus in;
    in.state = static_cast<ArmState>(raw);
    in.finger_init = {1, 1, 0};
    in.api_control = 1;
    in.torque_sensors = 1;
    ArmStatus out;
    ASSERT_EQ(parse_arm_status(encode_arm_status(in), out), PacketCheck::OK) << raw;
    EXPECT_EQ(out.state, in.state);
    EXPECT_EQ(out.finger_init, in.finger_init);
    EXPECT_EQ(out.api_control, 1);
    EXPECT_EQ(out.torque_sensors, 1);
  }
  for (const int bad : {7, 8, 100, 0xA8, 255}) {
    Packet p = encode_arm_status(ArmStatus{});
    p[body(4)] = static_cast<std::byte>(bad);
    ArmStatus out;
    out.api_control = 9;
    EXPECT_EQ(parse_arm_status(p, out), PacketCheck::BAD_VALUE) << bad;
    EXPECT_EQ(out.api_control, 9) << "out untouched on refusal";
  }
  // ERROR (25000) does not fit the byte: encoded as 255, which the parser refuses.
  ArmStatus err;
  err.state = ArmState::ERROR;
  const Packet e = encode_arm_status(err);
  EXPECT_EQ(std::to_integer<int>(e[body(4)]), 255);
  ArmStatus out;
  EXPECT_EQ(parse_arm_status(e, out), PacketCheck::BAD_VALUE);
}

TEST(JacoProtocol, ArmInfoSliceTwoHoldsTheRetractModeAtBody52) {
  EXPECT_EQ(ARM_INFO_STATE_OFFSET, 52U);
  for (const ArmState st : all_states()) {
    Packet p = header_only(2, 1, 200, 0);
    for (std::size_t i = 0; i < 52; ++i) p[body(i)] = std::byte{0x5A};  // the rest of the slice
    put_u32(p, body(52), static_cast<std::uint32_t>(static_cast<std::int32_t>(st)));
    ArmState out = ArmState::NOINIT;
    ASSERT_EQ(parse_arm_info_slice2(p, out), PacketCheck::OK) << to_string(st);
    EXPECT_EQ(out, st);
  }
  for (const std::int32_t bad :
       {7, -1, 24999, 25001, 0x01000000, std::numeric_limits<std::int32_t>::min()}) {
    Packet p{};
    put_u32(p, body(52), static_cast<std::uint32_t>(bad));
    ArmState out = ArmState::NORMAL;
    EXPECT_EQ(parse_arm_info_slice2(p, out), PacketCheck::BAD_VALUE) << bad;
    EXPECT_EQ(out, ArmState::NORMAL);
  }
}

TEST(JacoProtocol, ArmStateFromEveryValue) {
  for (std::int32_t raw = 0; raw <= 6; ++raw) {
    const auto s = arm_state_from(raw);
    ASSERT_TRUE(s.has_value()) << raw;
    EXPECT_EQ(static_cast<std::int32_t>(*s), raw);
  }
  ASSERT_TRUE(arm_state_from(25000).has_value());
  EXPECT_EQ(*arm_state_from(25000), ArmState::ERROR);
  for (const std::int32_t bad :
       {7, 8, -1, 24999, 25001, 100, std::numeric_limits<std::int32_t>::max(),
        std::numeric_limits<std::int32_t>::min()}) {
    EXPECT_FALSE(arm_state_from(bad).has_value()) << bad;
  }
}

TEST(JacoProtocol, EveryNameIsDistinctAndLowerCase) {
  const std::vector<std::pair<ArmState, std::string>> states = {
      {ArmState::NORMAL_TO_READY, "normal_to_ready"},
      {ArmState::READY_STANDBY, "ready_standby"},
      {ArmState::READY_TO_RETRACT, "ready_to_retract"},
      {ArmState::RETRACT_STANDBY, "retract_standby"},
      {ArmState::RETRACT_TO_READY, "retract_to_ready"},
      {ArmState::NORMAL, "normal"},
      {ArmState::NOINIT, "noinit"},
      {ArmState::ERROR, "error"}};
  for (const auto& [s, name] : states) EXPECT_EQ(to_string(s), name);
  EXPECT_STREQ(to_string(static_cast<ArmState>(7)), "unknown");

  EXPECT_STREQ(to_string(PacketCheck::OK), "ok");
  EXPECT_STREQ(to_string(PacketCheck::SHORT), "short");
  EXPECT_STREQ(to_string(PacketCheck::WRONG_COMMAND), "wrong_command");
  EXPECT_STREQ(to_string(PacketCheck::NOT_FINITE), "not_finite");
  EXPECT_STREQ(to_string(PacketCheck::BAD_STRING), "bad_string");
  EXPECT_STREQ(to_string(PacketCheck::BAD_VALUE), "bad_value");

  EXPECT_STREQ(to_string(ButtonAction::PRESS), "press");
  EXPECT_STREQ(to_string(ButtonAction::RELEASE), "release");
  EXPECT_STREQ(to_string(ButtonAction::WAIT), "wait");
  EXPECT_STREQ(to_string(ButtonAction::DONE), "done");
  EXPECT_STREQ(to_string(ButtonAction::REFUSE), "refuse");

  EXPECT_STREQ(to_string(Model::JACO_V1), "jaco_v1");
  EXPECT_STREQ(to_string(Model::JACO2), "jaco2");
}

// ---- commands (JACO.md 5) -----------------------------------------------------------------------

TEST(JacoProtocol, EveryCommandIsKnownByItsIdAndNamedAsLibkindrvDoes) {
  for (const auto& c : all_commands()) {
    EXPECT_EQ(static_cast<std::uint16_t>(c.command), c.id) << c.name;
    EXPECT_TRUE(is_known_command(c.id)) << c.name;
    EXPECT_STREQ(to_string(c.command), c.name);
  }
  std::size_t known = 0;
  for (std::uint32_t id = 0; id <= 0xFFFF; ++id) {
    known += is_known_command(static_cast<std::uint16_t>(id)) ? 1U : 0U;
  }
  EXPECT_EQ(known, all_commands().size());
  for (const int raw : {0, 2, 14, 16, 44, 112, 201, 304, 306, 307, 309, 0xFFFF}) {
    const auto id = static_cast<std::uint16_t>(raw);
    EXPECT_FALSE(is_known_command(id)) << id;
    EXPECT_STREQ(to_string(static_cast<Command>(id)), "unknown");
  }
}

// ---- models (JACO.md 8) -------------------------------------------------------------------------

TEST(JacoProtocol, DetectModelFromTheModelStringThenTheDspMajor) {
  const auto with = [](const char* model) {
    ClientInfo info;
    info.model.assign(model);
    return info;
  };
  Firmware v4, v5, v6;
  v4.dsp.major = 4;
  v5.dsp.major = 5;
  v6.dsp.major = 6;
  EXPECT_EQ(detect_model(with("JACO2 6DOF"), v4), Model::JACO2);
  EXPECT_EQ(detect_model(with("j2n6s300"), v4), Model::JACO2);
  EXPECT_EQ(detect_model(with("J2N6S300"), v4), Model::JACO2);
  EXPECT_EQ(detect_model(with("Kinova Jaco 2"), v4), Model::JACO2);
  EXPECT_EQ(detect_model(with("Jaco v1"), v6), Model::JACO_V1);  // the string wins
  EXPECT_EQ(detect_model(with("JACO"), v6), Model::JACO_V1);
  EXPECT_EQ(detect_model(with(""), v4), Model::JACO_V1);
  EXPECT_EQ(detect_model(with(""), v5), Model::JACO_V1);
  EXPECT_EQ(detect_model(with(""), v6), Model::JACO2);
  EXPECT_EQ(detect_model(with(""), Firmware{}), Model::JACO_V1);
  EXPECT_EQ(detect_model(with("MICO"), v6), Model::JACO2);
  EXPECT_EQ(detect_model(with("MICO"), v5), Model::JACO_V1);
  EXPECT_EQ(finger_closed(Model::JACO_V1), 55.0F);
  EXPECT_EQ(finger_closed(Model::JACO2), 6400.0F);
}

// ---- HOME / RETRACT through the virtual button (JACO.md 10.1) -----------------------------------

struct ButtonRow {
  ArmState state;
  ArmGoal goal;
  ButtonAction released;  // the button is up
  ButtonAction held;      // the button is down
};

TEST(JacoProtocol, NextButtonActionMatchesJacoMd101ForEveryStateGoalAndButton) {
  using A = ButtonAction;
  using S = ArmState;
  const std::vector<ButtonRow> table = {
      // Go HOME.
      {S::NORMAL_TO_READY, ArmGoal::HOME, A::PRESS, A::WAIT},      // press (then hold)
      {S::READY_STANDBY, ArmGoal::HOME, A::DONE, A::DONE},         // done
      {S::READY_TO_RETRACT, ArmGoal::HOME, A::PRESS, A::RELEASE},  // press reverses; held: flipped
      {S::RETRACT_STANDBY, ArmGoal::HOME, A::PRESS, A::WAIT},
      {S::RETRACT_TO_READY, ArmGoal::HOME, A::PRESS, A::WAIT},  // press, release, press
      {S::NORMAL, ArmGoal::HOME, A::PRESS, A::WAIT},
      {S::NOINIT, ArmGoal::HOME, A::PRESS, A::WAIT},
      {S::ERROR, ArmGoal::HOME, A::REFUSE, A::REFUSE},
      // Go RETRACT.
      {S::NORMAL_TO_READY, ArmGoal::RETRACT, A::REFUSE, A::REFUSE},  // only from HOME
      {S::READY_STANDBY, ArmGoal::RETRACT, A::PRESS, A::WAIT},       // press
      {S::READY_TO_RETRACT, ArmGoal::RETRACT, A::PRESS, A::WAIT},    // press, release, press
      {S::RETRACT_STANDBY, ArmGoal::RETRACT, A::DONE, A::DONE},
      {S::RETRACT_TO_READY, ArmGoal::RETRACT, A::PRESS, A::RELEASE},  // press
      {S::NORMAL, ArmGoal::RETRACT, A::REFUSE, A::REFUSE},
      {S::NOINIT, ArmGoal::RETRACT, A::REFUSE, A::REFUSE},
      {S::ERROR, ArmGoal::RETRACT, A::REFUSE, A::REFUSE},
  };
  ASSERT_EQ(table.size(), all_states().size() * 2);
  for (const ButtonRow& row : table) {
    const char* goal = row.goal == ArmGoal::HOME ? "home" : "retract";
    EXPECT_EQ(next_button_action(row.state, row.goal, false), row.released)
        << to_string(row.state) << " -> " << goal << ", released: got "
        << to_string(next_button_action(row.state, row.goal, false));
    EXPECT_EQ(next_button_action(row.state, row.goal, true), row.held)
        << to_string(row.state) << " -> " << goal << ", held: got "
        << to_string(next_button_action(row.state, row.goal, true));
  }
  // Coherent with the button: never press what is held, never release what is up.
  for (const ArmState s : all_states()) {
    for (const ArmGoal g : {ArmGoal::HOME, ArmGoal::RETRACT}) {
      EXPECT_NE(next_button_action(s, g, true), ButtonAction::PRESS) << to_string(s);
      EXPECT_NE(next_button_action(s, g, false), ButtonAction::RELEASE) << to_string(s);
      EXPECT_EQ(next_button_action(s, g, false) == ButtonAction::DONE, s == goal_state(g));
    }
  }
  EXPECT_EQ(goal_state(ArmGoal::HOME), ArmState::READY_STANDBY);
  EXPECT_EQ(goal_state(ArmGoal::RETRACT), ArmState::RETRACT_STANDBY);
}

/// The arm's button behaviour as JACO.md 10 / 10.1 describe it: a press while moving between HOME
/// and RETRACT reverses the direction; a press (or a held button) in NOINIT, NORMAL,
/// RETRACT_STANDBY or READY_STANDBY starts the move toward the next standby (NOINIT and NORMAL go
/// HOME); the arm moves only while the button is held, so a release pauses it where it is.
struct SimArm {
  static constexpr int PATH = 5;  // ticks between HOME (0) and RETRACT (PATH)
  ArmState state;
  bool held = false;
  int pos = 0;          // along the HOME..RETRACT path
  int normal_left = 0;  // ticks left of NORMAL_TO_READY

  SimArm(ArmState s, bool button, int at) : state(s), held(button), pos(at), normal_left(at) {}

  void start() {
    switch (state) {
      case ArmState::NOINIT:
      case ArmState::NORMAL:
        state = ArmState::NORMAL_TO_READY;
        normal_left = PATH;
        break;
      case ArmState::READY_STANDBY:
        state = ArmState::READY_TO_RETRACT;
        break;
      case ArmState::RETRACT_STANDBY:
        state = ArmState::RETRACT_TO_READY;
        break;
      default:
        break;
    }
  }
  void press() {
    ASSERT_FALSE(held) << "pressed a held button";
    held = true;
    if (state == ArmState::READY_TO_RETRACT) {
      state = ArmState::RETRACT_TO_READY;
    } else if (state == ArmState::RETRACT_TO_READY) {
      state = ArmState::READY_TO_RETRACT;
    } else if (state != ArmState::NORMAL_TO_READY) {  // NORMAL_TO_READY resumes: no way back
      start();
    }
  }
  void release() {
    ASSERT_TRUE(held) << "released a button that is up";
    held = false;
  }
  void tick() {
    if (!held) return;  // a released button pauses the arm
    switch (state) {
      case ArmState::NORMAL_TO_READY:
        if (--normal_left <= 0) {
          state = ArmState::READY_STANDBY;
          pos = 0;
        }
        break;
      case ArmState::RETRACT_TO_READY:
        if (--pos <= 0) {
          pos = 0;
          state = ArmState::READY_STANDBY;
        }
        break;
      case ArmState::READY_TO_RETRACT:
        if (++pos >= PATH) {
          pos = PATH;
          state = ArmState::RETRACT_STANDBY;
        }
        break;
      case ArmState::ERROR:
        break;
      default:
        start();
        break;  // a held button in a standby state starts the next move
    }
  }
};

struct Drive {
  std::vector<ButtonAction> actions;  // every action but WAIT, in order
  bool reached = false;
  int steps = 0;
};

/// Follows next_button_action: one poll, one action, one arm tick per step.
Drive drive(SimArm& arm, ArmGoal goal, int max_steps) {
  Drive d;
  for (; d.steps < max_steps; ++d.steps) {
    const ButtonAction a = next_button_action(arm.state, goal, arm.held);
    if (a != ButtonAction::WAIT) d.actions.push_back(a);
    if (a == ButtonAction::DONE) {
      if (arm.held) arm.release();  // "poll until the target state and release"
      d.reached = arm.state == goal_state(goal);
      return d;
    }
    if (a == ButtonAction::REFUSE) return d;
    if (a == ButtonAction::PRESS) arm.press();
    if (a == ButtonAction::RELEASE) arm.release();
    arm.tick();
  }
  return d;
}

int start_pos(ArmState s) {
  if (s == ArmState::RETRACT_STANDBY) return SimArm::PATH;
  if (s == ArmState::READY_STANDBY) return 0;
  return 2;  // mid-way along whichever move it is in
}

std::string names(const std::vector<ButtonAction>& actions) {
  std::string out;
  for (const ButtonAction a : actions) out += std::string(out.empty() ? "" : ", ") + to_string(a);
  return out;
}

TEST(JacoProtocol, FollowingTheButtonTableGivesTheSequencesOfJacoMd101) {
  using A = ButtonAction;
  using S = ArmState;
  struct Want {
    S state;
    ArmGoal goal;
    std::vector<A> actions;
  };
  const std::vector<Want> wants = {
      {S::NORMAL_TO_READY, ArmGoal::HOME, {A::PRESS, A::DONE}},
      {S::READY_STANDBY, ArmGoal::HOME, {A::DONE}},
      {S::READY_TO_RETRACT, ArmGoal::HOME, {A::PRESS, A::DONE}},
      {S::RETRACT_STANDBY, ArmGoal::HOME, {A::PRESS, A::DONE}},
      {S::RETRACT_TO_READY, ArmGoal::HOME, {A::PRESS, A::RELEASE, A::PRESS, A::DONE}},
      {S::NORMAL, ArmGoal::HOME, {A::PRESS, A::DONE}},
      {S::NOINIT, ArmGoal::HOME, {A::PRESS, A::DONE}},
      {S::ERROR, ArmGoal::HOME, {A::REFUSE}},
      {S::NORMAL_TO_READY, ArmGoal::RETRACT, {A::REFUSE}},
      {S::READY_STANDBY, ArmGoal::RETRACT, {A::PRESS, A::DONE}},
      {S::READY_TO_RETRACT, ArmGoal::RETRACT, {A::PRESS, A::RELEASE, A::PRESS, A::DONE}},
      {S::RETRACT_STANDBY, ArmGoal::RETRACT, {A::DONE}},
      {S::RETRACT_TO_READY, ArmGoal::RETRACT, {A::PRESS, A::DONE}},
      {S::NORMAL, ArmGoal::RETRACT, {A::REFUSE}},
      {S::NOINIT, ArmGoal::RETRACT, {A::REFUSE}},
      {S::ERROR, ArmGoal::RETRACT, {A::REFUSE}},
  };
  for (const Want& w : wants) {
    SimArm arm(w.state, false, start_pos(w.state));
    const Drive d = drive(arm, w.goal, 100);
    const std::string where =
        std::string(to_string(w.state)) + (w.goal == ArmGoal::HOME ? " -> home" : " -> retract");
    EXPECT_EQ(names(d.actions), names(w.actions)) << where;
    const bool refused = w.actions.back() == A::REFUSE;
    EXPECT_EQ(d.reached, !refused) << where;
    if (!refused) {
      EXPECT_EQ(arm.state, goal_state(w.goal)) << where;
      EXPECT_FALSE(arm.held) << where << ": the button is released at the end";
    }
  }
}

TEST(JacoProtocol, FollowingTheButtonTableReachesTheGoalFromEveryStateInBoundedSteps) {
  // Bound: a reversal costs at most the whole path back, plus a NORMAL_TO_READY leg and the
  // press / release steps; nothing may loop.
  constexpr int BOUND = 4 * SimArm::PATH + 8;
  for (const ArmState s : all_states()) {
    for (const bool held : {false, true}) {
      for (int at = 1; at < SimArm::PATH; ++at) {
        const int pos = s == ArmState::RETRACT_STANDBY ? SimArm::PATH
                        : s == ArmState::READY_STANDBY ? 0
                                                       : at;
        const std::string where =
            std::string(to_string(s)) + (held ? " held" : " up") + " at " + std::to_string(at);
        // HOME from everywhere but ERROR.
        SimArm home(s, held, pos);
        const Drive h = drive(home, ArmGoal::HOME, 1000);
        if (s == ArmState::ERROR) {
          EXPECT_FALSE(h.reached) << where;
          continue;
        }
        EXPECT_TRUE(h.reached) << where << ": " << names(h.actions);
        EXPECT_LE(h.steps, BOUND) << where;
        EXPECT_EQ(home.state, ArmState::READY_STANDBY) << where;
        // RETRACT directly where the table allows it, else after HOME (NORMAL / NOINIT /
        // NORMAL_TO_READY are refused: "only from HOME").
        SimArm retract(s, held, pos);
        Drive r = drive(retract, ArmGoal::RETRACT, 1000);
        const bool from_normal =
            s == ArmState::NORMAL || s == ArmState::NOINIT || s == ArmState::NORMAL_TO_READY;
        EXPECT_EQ(r.reached, !from_normal) << where;
        if (from_normal) {
          ASSERT_EQ(r.actions, std::vector<ButtonAction>{ButtonAction::REFUSE}) << where;
          if (retract.held) retract.release();
          ASSERT_TRUE(drive(retract, ArmGoal::HOME, 1000).reached) << where;
          r = drive(retract, ArmGoal::RETRACT, 1000);
          EXPECT_TRUE(r.reached) << where;
        }
        EXPECT_LE(r.steps, BOUND) << where;
        EXPECT_EQ(retract.state, ArmState::RETRACT_STANDBY) << where;
        EXPECT_FALSE(retract.held) << where;
      }
    }
  }
}

TEST(JacoProtocol, HomingThatFlipsToReadyToRetractIsReleasedAndPressedAgain) {
  // "While homing, if the state flips to READY_TO_RETRACT, release and press again" (10.1): the
  // button is held and the arm runs away from HOME.
  SimArm arm(ArmState::READY_TO_RETRACT, true, 1);
  const Drive d = drive(arm, ArmGoal::HOME, 100);
  EXPECT_EQ(names(d.actions), "release, press, done");
  EXPECT_TRUE(d.reached);
  EXPECT_FALSE(arm.held);
}

}  // namespace
}  // namespace orthoflow::drivers::jaco
