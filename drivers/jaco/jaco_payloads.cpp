// The JACO's payload codecs (jaco_protocol.hpp, "Payloads", JACO.md 6 and 7): arm states,
// trajectory points, joystick states and the nine-float, sensor, firmware, client-info, arm-status
// and arm-info replies. Each parser checks the device's bytes (finite floats, known values,
// printable strings) before it writes its output. The packet framing is in jaco_protocol.cpp.
#include "drivers/jaco/jaco_protocol.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/assert.hpp"
#include "drivers/jaco/jaco_packet_bytes.hpp"

namespace orthoflow::drivers::jaco {
namespace {

using detail::body_offset;
using detail::load_u16;
using detail::store_u16;

bool finite_floats(std::span<const std::byte, PACKET_BYTES> packet, std::size_t count) noexcept {
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(body_float(packet, i))) return false;
  }
  return true;
}

}  // namespace

const char* to_string(ArmState state) noexcept {
  switch (state) {
    case ArmState::NORMAL_TO_READY:
      return "normal_to_ready";
    case ArmState::READY_STANDBY:
      return "ready_standby";
    case ArmState::READY_TO_RETRACT:
      return "ready_to_retract";
    case ArmState::RETRACT_STANDBY:
      return "retract_standby";
    case ArmState::RETRACT_TO_READY:
      return "retract_to_ready";
    case ArmState::NORMAL:
      return "normal";
    case ArmState::NOINIT:
      return "noinit";
    case ArmState::ERROR:
      return "error";
  }
  return "unknown";
}

std::optional<ArmState> arm_state_from(std::int32_t raw) noexcept {
  if ((raw >= 0 && raw <= 6) || raw == static_cast<std::int32_t>(ArmState::ERROR)) {
    return static_cast<ArmState>(raw);
  }
  return std::nullopt;
}

Packet encode_trajectory(const TrajectoryPoint& point) noexcept {
  Packet packet =
      make_packet({1, 1, static_cast<std::uint16_t>(Command::SEND_BASIC_TRAJECTORY), 48});
  for (std::size_t i = 0; i < JOINTS; ++i) set_body_float(packet, i, point.target[i]);
  for (std::size_t i = 0; i < FINGERS; ++i) set_body_float(packet, JOINTS + i, point.fingers[i]);
  set_body_float(packet, 9, point.delay_s);
  set_body_i32(packet, 40, static_cast<std::int32_t>(point.hand_mode));
  set_body_i32(packet, 44, static_cast<std::int32_t>(point.type));
  return packet;
}

PacketCheck decode_trajectory(std::span<const std::byte, PACKET_BYTES> packet,
                              TrajectoryPoint& out) noexcept {
  if (!finite_floats(packet, 10)) return PacketCheck::NOT_FINITE;
  const std::int32_t hand = body_i32(packet, 40);
  const std::int32_t type = body_i32(packet, 44);
  const bool type_ok = type == 0 || type == 1 || type == 2 || type == 7 || type == 8 || type == 12;
  if (hand < 0 || hand > 2 || !type_ok) return PacketCheck::BAD_VALUE;
  for (std::size_t i = 0; i < JOINTS; ++i) out.target[i] = body_float(packet, i);
  for (std::size_t i = 0; i < FINGERS; ++i) out.fingers[i] = body_float(packet, JOINTS + i);
  out.delay_s = body_float(packet, 9);
  out.hand_mode = static_cast<HandMode>(hand);
  out.type = static_cast<PositionType>(type);
  return PacketCheck::OK;
}

bool JoystickState::is_release() const noexcept {
  return std::all_of(buttons.begin(), buttons.end(), [](std::uint16_t b) { return b == 0; }) &&
         std::all_of(axes.begin(), axes.end(), [](float a) { return a == 0.0F; });
}

Packet encode_joystick(const JoystickState& state) noexcept {
  Packet packet = make_packet({1, 1, static_cast<std::uint16_t>(Command::JOYSTICK), 56});
  for (std::size_t i = 0; i < state.buttons.size(); ++i) {
    store_u16(packet.data() + body_offset(2 * i), state.buttons[i]);
  }
  for (std::size_t i = 0; i < state.axes.size(); ++i) set_body_float(packet, 8 + i, state.axes[i]);
  return packet;
}

PacketCheck decode_joystick(std::span<const std::byte, PACKET_BYTES> packet,
                            JoystickState& out) noexcept {
  JoystickState state;
  for (std::size_t i = 0; i < state.buttons.size(); ++i) {
    state.buttons[i] = load_u16(packet.data() + body_offset(2 * i));
    if (state.buttons[i] > 1) return PacketCheck::BAD_VALUE;
  }
  for (std::size_t i = 0; i < state.axes.size(); ++i) {
    state.axes[i] = body_float(packet, 8 + i);
    if (!std::isfinite(state.axes[i])) return PacketCheck::NOT_FINITE;
  }
  out = state;
  return PacketCheck::OK;
}

JoystickState home_button_press() noexcept {
  JoystickState state;
  state.buttons[HOME_BUTTON] = 1;
  return state;
}

PacketCheck parse_nine(std::span<const std::byte, PACKET_BYTES> reply, NineFloats& out) noexcept {
  if (!finite_floats(reply, JOINTS + FINGERS)) return PacketCheck::NOT_FINITE;
  for (std::size_t i = 0; i < JOINTS; ++i) out.values[i] = body_float(reply, i);
  for (std::size_t i = 0; i < FINGERS; ++i) out.fingers[i] = body_float(reply, JOINTS + i);
  return PacketCheck::OK;
}

Packet encode_nine(Command command, const NineFloats& values) noexcept {
  Packet packet = make_packet({1, 1, static_cast<std::uint16_t>(command), 36});
  for (std::size_t i = 0; i < JOINTS; ++i) set_body_float(packet, i, values.values[i]);
  for (std::size_t i = 0; i < FINGERS; ++i) set_body_float(packet, JOINTS + i, values.fingers[i]);
  return packet;
}

PacketCheck parse_sensor_info(std::span<const std::byte, PACKET_BYTES> reply,
                              SensorInfo& out) noexcept {
  if (!finite_floats(reply, BODY_FLOATS)) return PacketCheck::NOT_FINITE;
  out.voltage_v = body_float(reply, 0);
  out.current_a = body_float(reply, 1);
  for (std::size_t i = 0; i < 3; ++i) out.accel_g[i] = body_float(reply, 2 + i);
  for (std::size_t i = 0; i < JOINTS; ++i) out.actuator_temp_c[i] = body_float(reply, 5 + i);
  for (std::size_t i = 0; i < FINGERS; ++i) out.finger_temp_c[i] = body_float(reply, 11 + i);
  return PacketCheck::OK;
}

Packet encode_sensor_info(const SensorInfo& info) noexcept {
  Packet packet =
      make_packet({1, 1, static_cast<std::uint16_t>(Command::GET_SENSOR_INFO), BODY_BYTES});
  set_body_float(packet, 0, info.voltage_v);
  set_body_float(packet, 1, info.current_a);
  for (std::size_t i = 0; i < 3; ++i) set_body_float(packet, 2 + i, info.accel_g[i]);
  for (std::size_t i = 0; i < JOINTS; ++i) set_body_float(packet, 5 + i, info.actuator_temp_c[i]);
  for (std::size_t i = 0; i < FINGERS; ++i) set_body_float(packet, 11 + i, info.finger_temp_c[i]);
  return packet;
}

FirmwareVersion firmware_word(std::uint32_t word) noexcept {
  return {static_cast<std::uint8_t>((word >> 16U) & 0xFFU),
          static_cast<std::uint8_t>((word >> 8U) & 0xFFU), static_cast<std::uint8_t>(word & 0xFFU)};
}

namespace {
std::uint32_t firmware_bits(const FirmwareVersion& v) noexcept {
  return (std::uint32_t{v.major} << 16U) | (std::uint32_t{v.minor} << 8U) | v.patch;
}
}  // namespace

PacketCheck parse_firmware(std::span<const std::byte, PACKET_BYTES> reply, Firmware& out) noexcept {
  Firmware firmware;
  firmware.dsp = firmware_word(body_u32(reply, 0));
  for (std::size_t i = 0; i < JOINTS; ++i) {
    firmware.actuators[i] = firmware_word(body_u32(reply, 4 * (1 + i)));
  }
  for (std::size_t i = 0; i < FINGERS; ++i) {
    firmware.fingers[i] = firmware_word(body_u32(reply, 4 * (7 + i)));
  }
  // A DSP that reports major 0 is not running firmware we know (a corrupted "1.0.8.0" arm still
  // says 1): refuse it rather than guess the joystick layout.
  if (firmware.dsp.major == 0) return PacketCheck::BAD_VALUE;
  out = firmware;
  return PacketCheck::OK;
}

Packet encode_firmware(const Firmware& firmware) noexcept {
  Packet packet = make_packet({1, 1, static_cast<std::uint16_t>(Command::GET_FIRMWARE), 52});
  set_body_u32(packet, 0, firmware_bits(firmware.dsp));
  for (std::size_t i = 0; i < JOINTS; ++i) {
    set_body_u32(packet, 4 * (1 + i), firmware_bits(firmware.actuators[i]));
  }
  for (std::size_t i = 0; i < FINGERS; ++i) {
    set_body_u32(packet, 4 * (7 + i), firmware_bits(firmware.fingers[i]));
  }
  return packet;
}

PacketCheck parse_client_info(std::span<const std::byte> slices, ClientInfo& out) noexcept {
  OF_ASSERT(slices.size() == 2 * BODY_BYTES, "jaco::parse_client_info: needs slices 1 and 2");
  ClientInfo info;
  core::FixedText<CLIENT_STRING_BYTES>* fields[] = {&info.client_id, &info.name, &info.organisation,
                                                    &info.serial, &info.model};
  for (std::size_t f = 0; f < 5; ++f) {
    const std::byte* s = slices.data() + f * CLIENT_STRING_BYTES;
    std::size_t length = 0;
    while (length < CLIENT_STRING_BYTES && s[length] != std::byte{0}) {
      const auto c = std::to_integer<unsigned>(s[length]);
      if (c < 0x20 || c > 0x7E) return PacketCheck::BAD_STRING;
      ++length;
    }
    if (length == CLIENT_STRING_BYTES) return PacketCheck::BAD_STRING;
    fields[f]->assign({reinterpret_cast<const char*>(s), length});
  }
  out = info;
  return PacketCheck::OK;
}

void encode_client_info(const ClientInfo& info, std::span<std::byte, 2 * BODY_BYTES> out) noexcept {
  std::fill(out.begin(), out.end(), std::byte{0});
  const core::FixedText<CLIENT_STRING_BYTES>* fields[] = {
      &info.client_id, &info.name, &info.organisation, &info.serial, &info.model};
  for (std::size_t f = 0; f < 5; ++f) {
    const std::string_view text = fields[f]->view();
    const std::size_t n = std::min(text.size(), CLIENT_STRING_BYTES - 1);
    std::memcpy(out.data() + f * CLIENT_STRING_BYTES, text.data(), n);
  }
}

PacketCheck parse_arm_status(std::span<const std::byte, PACKET_BYTES> reply,
                             ArmStatus& out) noexcept {
  const auto byte = [&](std::size_t i) {
    return std::to_integer<std::uint8_t>(reply[body_offset(i)]);
  };
  const std::optional<ArmState> state = arm_state_from(byte(4));
  if (!state) return PacketCheck::BAD_VALUE;
  ArmStatus status;
  status.state = *state;
  for (std::size_t i = 0; i < FINGERS; ++i) status.finger_init[i] = byte(i);
  status.api_control = byte(6);
  status.force_control = byte(10);
  status.current_limitation = byte(11);
  status.torque_sensors = byte(14);
  out = status;
  return PacketCheck::OK;
}

Packet encode_arm_status(const ArmStatus& status) noexcept {
  Packet packet = make_packet({1, 1, static_cast<std::uint16_t>(Command::GET_ARM_STATUS), 16});
  const auto put = [&](std::size_t i, std::uint8_t v) {
    packet[body_offset(i)] = static_cast<std::byte>(v);
  };
  for (std::size_t i = 0; i < FINGERS; ++i) put(i, status.finger_init[i]);
  // Only states 0..6 fit the status byte; ERROR (25000) is reported as 255, which parses as bad.
  const auto raw = static_cast<std::int32_t>(status.state);
  put(4, raw >= 0 && raw <= 6 ? static_cast<std::uint8_t>(raw) : std::uint8_t{255});
  put(6, status.api_control);
  put(10, status.force_control);
  put(11, status.current_limitation);
  put(14, status.torque_sensors);
  return packet;
}

PacketCheck parse_arm_info_slice2(std::span<const std::byte, PACKET_BYTES> reply,
                                  ArmState& out) noexcept {
  const std::optional<ArmState> state = arm_state_from(body_i32(reply, ARM_INFO_STATE_OFFSET));
  if (!state) return PacketCheck::BAD_VALUE;
  out = *state;
  return PacketCheck::OK;
}

}  // namespace orthoflow::drivers::jaco
