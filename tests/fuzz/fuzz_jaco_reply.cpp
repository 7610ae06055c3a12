// Fuzzes the JACO packet codec (drivers/jaco/jaco_protocol.hpp) with arbitrary arm bytes: the input
// is cut into 64-byte packets (a trailing partial one zero-padded) and every packet goes through
// the reply check for every known command, the header reader and every payload parser; the first
// 112 bytes also go through the client-info parser. No input may crash or hit UB, and whatever a
// parser accepts must be finite and in range, and must survive its encoder and the parser again
// unchanged (for the payloads that are all fields: bit for bit against the input bytes).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>

#include "drivers/jaco/jaco_protocol.hpp"

namespace jaco = orthoflow::drivers::jaco;

namespace {

constexpr std::array<jaco::Command, 24> COMMANDS = {
    jaco::Command::GET_CLIENT_INFO,
    jaco::Command::GET_ANG_POS,
    jaco::Command::GET_FIRMWARE,
    jaco::Command::SET_CONTROL_ANGULAR,
    jaco::Command::SET_CONTROL_CARTESIAN,
    jaco::Command::START_FORCE_CONTROL,
    jaco::Command::STOP_FORCE_CONTROL,
    jaco::Command::GET_ARM_STATUS,
    jaco::Command::GET_CART_INFO,
    jaco::Command::GET_ANG_INFO,
    jaco::Command::GET_CART_COMMAND,
    jaco::Command::GET_ANG_COMMAND,
    jaco::Command::GET_CART_FORCE,
    jaco::Command::GET_ANG_FORCE,
    jaco::Command::GET_ANG_CURRENT,
    jaco::Command::GET_SENSOR_INFO,
    jaco::Command::GET_ANG_CURRENT_MOTOR,
    jaco::Command::GET_ANG_VEL,
    jaco::Command::GET_ARM_INFO,
    jaco::Command::ERASE_TRAJECTORIES,
    jaco::Command::START_API_CONTROL,
    jaco::Command::STOP_API_CONTROL,
    jaco::Command::JOYSTICK,
    jaco::Command::SEND_BASIC_TRAJECTORY,
};

void require(bool ok) {
  if (!ok) __builtin_trap();
}

template <std::size_t N>
bool finite(const std::array<float, N>& values) {
  return std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); });
}
template <std::size_t N>
bool same_bits(const std::array<float, N>& a, const std::array<float, N>& b) {
  return std::memcmp(a.data(), b.data(), sizeof(float) * N) == 0;
}
bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
/// Body bytes [from, to) of two packets are equal.
bool same_body(const jaco::Packet& a, const jaco::Packet& b, std::size_t from, std::size_t to) {
  return std::memcmp(a.data() + jaco::HEADER_BYTES + from, b.data() + jaco::HEADER_BYTES + from,
                     to - from) == 0;
}
bool same_version(const jaco::FirmwareVersion& a, const jaco::FirmwareVersion& b) {
  return a.major == b.major && a.minor == b.minor && a.patch == b.patch;
}
bool same_firmware(const jaco::Firmware& a, const jaco::Firmware& b) {
  bool same = same_version(a.dsp, b.dsp);
  for (std::size_t i = 0; i < jaco::JOINTS; ++i)
    same &= same_version(a.actuators[i], b.actuators[i]);
  for (std::size_t i = 0; i < jaco::FINGERS; ++i) same &= same_version(a.fingers[i], b.fingers[i]);
  return same;
}
bool valid_state(jaco::ArmState s) {
  return jaco::arm_state_from(static_cast<std::int32_t>(s)).has_value() &&
         std::string_view(jaco::to_string(s)) != "unknown";
}

void check_buttons(jaco::ArmState state) {
  for (const jaco::ArmGoal goal : {jaco::ArmGoal::HOME, jaco::ArmGoal::RETRACT}) {
    for (const bool pressed : {false, true}) {
      const jaco::ButtonAction a = jaco::next_button_action(state, goal, pressed);
      require(!(a == jaco::ButtonAction::PRESS && pressed));
      require(!(a == jaco::ButtonAction::RELEASE && !pressed));
      require((a == jaco::ButtonAction::DONE) == (state == jaco::goal_state(goal)));
      require(std::string_view(jaco::to_string(a)) != "unknown");
    }
  }
}

void check_packet(const jaco::Packet& p) {
  // Header: read, rebuilt, read again.
  const jaco::PacketHeader h = jaco::read_header(p);
  const jaco::Packet rebuilt = jaco::make_packet(h);
  require(std::memcmp(rebuilt.data(), p.data(), jaco::HEADER_BYTES) == 0);
  const jaco::PacketHeader h2 = jaco::read_header(rebuilt);
  require(h2.id_packet == h.id_packet && h2.packet_quantity == h.packet_quantity &&
          h2.command_id == h.command_id && h2.command_size == h.command_size);
  const bool known = jaco::is_known_command(h.command_id);
  require(known == (std::string_view(jaco::to_string(static_cast<jaco::Command>(h.command_id))) !=
                    "unknown"));
  std::size_t matches = 0;
  for (const jaco::Command c : COMMANDS) {
    const jaco::PacketCheck r = jaco::check_reply(p, c);
    const bool same = h.command_id == static_cast<std::uint16_t>(c);
    require(r == (same ? jaco::PacketCheck::OK : jaco::PacketCheck::WRONG_COMMAND));
    matches += same ? 1U : 0U;
  }
  require(matches == (known ? 1U : 0U));

  // Nine floats (15, 104-114).
  jaco::NineFloats nine;
  if (jaco::parse_nine(p, nine) == jaco::PacketCheck::OK) {
    require(finite(nine.values) && finite(nine.fingers));
    const jaco::Packet again = jaco::encode_nine(jaco::Command::GET_ANG_POS, nine);
    require(same_body(again, p, 0, 36));
    jaco::NineFloats back;
    require(jaco::parse_nine(again, back) == jaco::PacketCheck::OK);
    require(same_bits(back.values, nine.values) && same_bits(back.fingers, nine.fingers));
  }

  // Sensor info: all 14 floats are fields, so the encoder gives the body back.
  jaco::SensorInfo sensors;
  if (jaco::parse_sensor_info(p, sensors) == jaco::PacketCheck::OK) {
    require(std::isfinite(sensors.voltage_v) && std::isfinite(sensors.current_a) &&
            finite(sensors.accel_g) && finite(sensors.actuator_temp_c) &&
            finite(sensors.finger_temp_c));
    const jaco::Packet again = jaco::encode_sensor_info(sensors);
    require(same_body(again, p, 0, jaco::BODY_BYTES));
    jaco::SensorInfo back;
    require(jaco::parse_sensor_info(again, back) == jaco::PacketCheck::OK);
    require(same_bits(back.voltage_v, sensors.voltage_v) &&
            same_bits(back.actuator_temp_c, sensors.actuator_temp_c));
  }

  // Firmware: words 0-9, low 24 bits each.
  jaco::Firmware firmware;
  if (jaco::parse_firmware(p, firmware) == jaco::PacketCheck::OK) {
    require(firmware.dsp.major != 0);
    const jaco::Packet again = jaco::encode_firmware(firmware);
    for (std::size_t w = 0; w < 10; ++w) {
      require((jaco::body_u32(again, 4 * w) & 0xFFFFFFU) == (jaco::body_u32(p, 4 * w) & 0xFFFFFFU));
    }
    jaco::Firmware back;
    require(jaco::parse_firmware(again, back) == jaco::PacketCheck::OK);
    require(same_firmware(back, firmware));
    require(firmware.dsp.dsp5() == (firmware.dsp.major >= 5));
  }

  // Arm status (62): bytes 0, 1, 2, 4, 6, 10, 11, 14.
  jaco::ArmStatus status;
  if (jaco::parse_arm_status(p, status) == jaco::PacketCheck::OK) {
    const auto raw = static_cast<std::int32_t>(status.state);
    require(raw >= 0 && raw <= 6 && valid_state(status.state));
    const jaco::Packet again = jaco::encode_arm_status(status);
    for (const std::size_t i : {0U, 1U, 2U, 4U, 6U, 10U, 11U, 14U}) {
      require(again[jaco::HEADER_BYTES + i] == p[jaco::HEADER_BYTES + i]);
    }
    jaco::ArmStatus back;
    require(jaco::parse_arm_status(again, back) == jaco::PacketCheck::OK);
    require(back.state == status.state && back.finger_init == status.finger_init &&
            back.api_control == status.api_control && back.force_control == status.force_control &&
            back.current_limitation == status.current_limitation &&
            back.torque_sensors == status.torque_sensors);
    check_buttons(status.state);
  }

  // Arm info slice 2 (200): the retract mode at body 52.
  jaco::ArmState state = jaco::ArmState::NOINIT;
  if (jaco::parse_arm_info_slice2(p, state) == jaco::PacketCheck::OK) {
    require(valid_state(state));
    require(static_cast<std::int32_t>(state) == jaco::body_i32(p, jaco::ARM_INFO_STATE_OFFSET));
    check_buttons(state);
  }

  // Trajectory point (308): body 0-47 are fields, 48-55 encode as zero.
  jaco::TrajectoryPoint point;
  if (jaco::decode_trajectory(p, point) == jaco::PacketCheck::OK) {
    require(finite(point.target) && finite(point.fingers) && std::isfinite(point.delay_s));
    const auto hand = static_cast<std::int32_t>(point.hand_mode);
    const auto type = static_cast<std::int32_t>(point.type);
    require(hand >= 0 && hand <= 2);
    require(type == 0 || type == 1 || type == 2 || type == 7 || type == 8 || type == 12);
    const jaco::Packet again = jaco::encode_trajectory(point);
    require(same_body(again, p, 0, 48));
    require(jaco::read_header(again).command_size == 48);
    jaco::TrajectoryPoint back;
    require(jaco::decode_trajectory(again, back) == jaco::PacketCheck::OK);
    require(same_bits(back.target, point.target) && same_bits(back.fingers, point.fingers) &&
            same_bits(back.delay_s, point.delay_s) && back.hand_mode == point.hand_mode &&
            back.type == point.type);
  }

  // Joystick (305): the whole body is fields.
  jaco::JoystickState joystick;
  if (jaco::decode_joystick(p, joystick) == jaco::PacketCheck::OK) {
    require(finite(joystick.axes));
    require(std::all_of(joystick.buttons.begin(), joystick.buttons.end(),
                        [](std::uint16_t b) { return b <= 1; }));
    const jaco::Packet again = jaco::encode_joystick(joystick);
    require(same_body(again, p, 0, jaco::BODY_BYTES));
    jaco::JoystickState back;
    require(jaco::decode_joystick(again, back) == jaco::PacketCheck::OK);
    require(back.buttons == joystick.buttons && same_bits(back.axes, joystick.axes));
    bool zero_body = true;
    for (std::size_t i = jaco::HEADER_BYTES; i < jaco::PACKET_BYTES; ++i) {
      zero_body &= p[i] == std::byte{0};
    }
    if (zero_body) require(joystick.is_release());
    if (joystick.is_release()) {
      require(std::all_of(joystick.buttons.begin(), joystick.buttons.end(),
                          [](std::uint16_t b) { return b == 0; }));
    }
  }
}

void check_client_info(std::span<const std::byte> slices, const jaco::Firmware& firmware) {
  jaco::ClientInfo info;
  if (jaco::parse_client_info(slices, info) != jaco::PacketCheck::OK) return;
  const orthoflow::core::FixedText<jaco::CLIENT_STRING_BYTES>* fields[] = {
      &info.client_id, &info.name, &info.organisation, &info.serial, &info.model};
  for (std::size_t f = 0; f < 5; ++f) {
    const std::string_view text = fields[f]->view();
    require(text.size() < jaco::CLIENT_STRING_BYTES);
    for (const char c : text) require(c >= 0x20 && c <= 0x7E);
    // The string is the input's bytes up to the NUL.
    require(std::memcmp(text.data(), slices.data() + f * jaco::CLIENT_STRING_BYTES, text.size()) ==
            0);
    require(slices[f * jaco::CLIENT_STRING_BYTES + text.size()] == std::byte{0});
  }
  std::array<std::byte, 2 * jaco::BODY_BYTES> again{};
  jaco::encode_client_info(info, again);
  jaco::ClientInfo back;
  require(jaco::parse_client_info(again, back) == jaco::PacketCheck::OK);
  require(back.client_id == info.client_id && back.name == info.name &&
          back.organisation == info.organisation && back.serial == info.serial &&
          back.model == info.model);
  const jaco::Model model = jaco::detect_model(info, firmware);
  require(model == jaco::Model::JACO_V1 || model == jaco::Model::JACO2);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> in = std::as_bytes(std::span(data, size));

  // The reply check on the raw input, whatever its length.
  for (const jaco::Command c : COMMANDS) {
    const jaco::PacketCheck r = jaco::check_reply(in, c);
    if (size < jaco::PACKET_BYTES) {
      require(r == jaco::PacketCheck::SHORT);
    } else {
      const auto id = static_cast<std::uint16_t>(std::to_integer<unsigned>(in[4]) |
                                                 std::to_integer<unsigned>(in[5]) << 8U);
      require(r == (id == static_cast<std::uint16_t>(c) ? jaco::PacketCheck::OK
                                                        : jaco::PacketCheck::WRONG_COMMAND));
    }
    require(jaco::check_reply(in.first(std::min(size, jaco::PACKET_BYTES - 1)), c) ==
            jaco::PacketCheck::SHORT);
  }

  // Every 64-byte packet; the last partial one zero-padded.
  jaco::Firmware first_firmware;
  bool have_firmware = false;
  for (std::size_t at = 0; at < size; at += jaco::PACKET_BYTES) {
    jaco::Packet packet{};
    const std::size_t n = std::min(jaco::PACKET_BYTES, size - at);
    std::memcpy(packet.data(), in.data() + at, n);
    check_packet(packet);
    if (!have_firmware)
      have_firmware = jaco::parse_firmware(packet, first_firmware) == jaco::PacketCheck::OK;
  }

  // Client-info slices 1 and 2: the first 112 bytes.
  if (size >= 2 * jaco::BODY_BYTES)
    check_client_info(in.first(2 * jaco::BODY_BYTES), first_firmware);
  return 0;
}
