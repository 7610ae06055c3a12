#include "drivers/jaco_protocol.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/assert.hpp"

namespace orthoflow::drivers::jaco {
namespace {

std::uint16_t load_u16(const std::byte* p) noexcept {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(p[0]) |
                                    (std::to_integer<unsigned>(p[1]) << 8U));
}
void store_u16(std::byte* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::byte>(v & 0xFFU);
  p[1] = static_cast<std::byte>(v >> 8U);
}
std::uint32_t load_u32(const std::byte* p) noexcept {
  std::uint32_t v = 0;
  for (unsigned i = 0; i < 4; ++i) v |= std::to_integer<std::uint32_t>(p[i]) << (8U * i);
  return v;
}
void store_u32(std::byte* p, std::uint32_t v) noexcept {
  for (unsigned i = 0; i < 4; ++i) p[i] = static_cast<std::byte>((v >> (8U * i)) & 0xFFU);
}

constexpr std::size_t body_offset(std::size_t byte) noexcept { return HEADER_BYTES + byte; }

bool finite_floats(std::span<const std::byte, PACKET_BYTES> packet, std::size_t count) noexcept {
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(body_float(packet, i))) return false;
  }
  return true;
}

}  // namespace

const char* to_string(Command command) noexcept {
  switch (command) {
    case Command::GET_CLIENT_INFO:
      return "get_client_info";
    case Command::GET_ANG_POS:
      return "get_ang_pos";
    case Command::GET_FIRMWARE:
      return "get_firmware";
    case Command::SET_CONTROL_ANGULAR:
      return "set_control_angular";
    case Command::SET_CONTROL_CARTESIAN:
      return "set_control_cartesian";
    case Command::START_FORCE_CONTROL:
      return "start_force_control";
    case Command::STOP_FORCE_CONTROL:
      return "stop_force_control";
    case Command::GET_ARM_STATUS:
      return "get_arm_status";
    case Command::GET_CART_INFO:
      return "get_cart_info";
    case Command::GET_ANG_INFO:
      return "get_ang_info";
    case Command::GET_CART_COMMAND:
      return "get_cart_command";
    case Command::GET_ANG_COMMAND:
      return "get_ang_command";
    case Command::GET_CART_FORCE:
      return "get_cart_force";
    case Command::GET_ANG_FORCE:
      return "get_ang_force";
    case Command::GET_ANG_CURRENT:
      return "get_ang_current";
    case Command::GET_SENSOR_INFO:
      return "get_sensor_info";
    case Command::GET_ANG_CURRENT_MOTOR:
      return "get_ang_current_motor";
    case Command::GET_ANG_VEL:
      return "get_ang_vel";
    case Command::GET_ARM_INFO:
      return "get_arm_info";
    case Command::ERASE_TRAJECTORIES:
      return "erase_trajectories";
    case Command::START_API_CONTROL:
      return "start_api_control";
    case Command::STOP_API_CONTROL:
      return "stop_api_control";
    case Command::JOYSTICK:
      return "joystick";
    case Command::SEND_BASIC_TRAJECTORY:
      return "send_basic_trajectory";
  }
  return "unknown";
}

bool is_known_command(std::uint16_t id) noexcept {
  return std::string_view(to_string(static_cast<Command>(id))) != "unknown";
}

const char* to_string(PacketCheck check) noexcept {
  switch (check) {
    case PacketCheck::OK:
      return "ok";
    case PacketCheck::SHORT:
      return "short";
    case PacketCheck::WRONG_COMMAND:
      return "wrong_command";
    case PacketCheck::NOT_FINITE:
      return "not_finite";
    case PacketCheck::BAD_STRING:
      return "bad_string";
    case PacketCheck::BAD_VALUE:
      return "bad_value";
  }
  return "unknown";
}

Packet make_packet(const PacketHeader& header) noexcept {
  Packet packet{};  // always zero all 64 bytes first (JACO.md 3)
  store_u16(packet.data() + 0, header.id_packet);
  store_u16(packet.data() + 2, header.packet_quantity);
  store_u16(packet.data() + 4, header.command_id);
  store_u16(packet.data() + 6, header.command_size);
  return packet;
}

Packet make_request(Command command, std::uint16_t id_packet) noexcept {
  return make_packet({id_packet, 1, static_cast<std::uint16_t>(command), 1});
}

Packet make_plain_command(Command command) noexcept {
  // libkindrv sends 1 for set-cartesian-control and 0 for the others (JACO.md 3); kept as seen.
  const std::uint16_t size = command == Command::SET_CONTROL_CARTESIAN ? 1 : 0;
  return make_packet({1, 1, static_cast<std::uint16_t>(command), size});
}

PacketHeader read_header(std::span<const std::byte, PACKET_BYTES> packet) noexcept {
  return {load_u16(packet.data() + 0), load_u16(packet.data() + 2), load_u16(packet.data() + 4),
          load_u16(packet.data() + 6)};
}

float body_float(std::span<const std::byte, PACKET_BYTES> packet, std::size_t index) noexcept {
  OF_ASSERT(index < BODY_FLOATS, "jaco::body_float: index out of range");
  const std::uint32_t bits = load_u32(packet.data() + body_offset(4 * index));
  float value = 0.0F;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

void set_body_float(Packet& packet, std::size_t index, float value) noexcept {
  OF_ASSERT(index < BODY_FLOATS, "jaco::set_body_float: index out of range");
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  store_u32(packet.data() + body_offset(4 * index), bits);
}

std::uint32_t body_u32(std::span<const std::byte, PACKET_BYTES> packet,
                       std::size_t offset) noexcept {
  OF_ASSERT(offset + 4 <= BODY_BYTES, "jaco::body_u32: offset out of range");
  return load_u32(packet.data() + body_offset(offset));
}
void set_body_u32(Packet& packet, std::size_t offset, std::uint32_t value) noexcept {
  OF_ASSERT(offset + 4 <= BODY_BYTES, "jaco::set_body_u32: offset out of range");
  store_u32(packet.data() + body_offset(offset), value);
}
std::int32_t body_i32(std::span<const std::byte, PACKET_BYTES> packet,
                      std::size_t offset) noexcept {
  return static_cast<std::int32_t>(body_u32(packet, offset));
}
void set_body_i32(Packet& packet, std::size_t offset, std::int32_t value) noexcept {
  set_body_u32(packet, offset, static_cast<std::uint32_t>(value));
}

PacketCheck check_reply(std::span<const std::byte> reply, Command request) noexcept {
  if (reply.size() < PACKET_BYTES) return PacketCheck::SHORT;
  if (load_u16(reply.data() + 4) != static_cast<std::uint16_t>(request)) {
    return PacketCheck::WRONG_COMMAND;
  }
  return PacketCheck::OK;
}

// ---- payloads -----------------------------------------------------------------------------------

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

// ---- models -------------------------------------------------------------------------------------

const char* to_string(Model model) noexcept { return model == Model::JACO2 ? "jaco2" : "jaco_v1"; }

Model detect_model(const ClientInfo& info, const Firmware& firmware) noexcept {
  std::string_view m = info.model.view();
  std::array<char, CLIENT_STRING_BYTES> lower{};
  const std::size_t n = std::min(m.size(), lower.size());
  for (std::size_t i = 0; i < n; ++i) {
    const char c = m[i];
    lower[i] = (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
  }
  const std::string_view text(lower.data(), n);
  const bool jaco = text.find("jaco") != std::string_view::npos;
  if (text.find("jaco2") != std::string_view::npos ||
      text.find("jaco 2") != std::string_view::npos ||
      (jaco && text.find("v2") != std::string_view::npos) || text.rfind("j2", 0) == 0) {
    return Model::JACO2;
  }
  if (jaco) return Model::JACO_V1;
  return firmware.dsp.major >= 6 ? Model::JACO2 : Model::JACO_V1;
}

float finger_closed(Model model) noexcept { return model == Model::JACO2 ? 6400.0F : 55.0F; }

// ---- home / retract -----------------------------------------------------------------------------

const char* to_string(ButtonAction action) noexcept {
  switch (action) {
    case ButtonAction::PRESS:
      return "press";
    case ButtonAction::RELEASE:
      return "release";
    case ButtonAction::WAIT:
      return "wait";
    case ButtonAction::DONE:
      return "done";
    case ButtonAction::REFUSE:
      return "refuse";
  }
  return "unknown";
}

ArmState goal_state(ArmGoal goal) noexcept {
  return goal == ArmGoal::HOME ? ArmState::READY_STANDBY : ArmState::RETRACT_STANDBY;
}

ButtonAction next_button_action(ArmState state, ArmGoal goal, bool pressed) noexcept {
  if (state == goal_state(goal)) return ButtonAction::DONE;
  // A press while the arm moves in a direction reverses it (JACO.md 10.1); while it moves away from
  // the goal with the button held, let go first, then press again.
  const ArmState toward =
      goal == ArmGoal::HOME ? ArmState::RETRACT_TO_READY : ArmState::READY_TO_RETRACT;
  const ArmState away =
      goal == ArmGoal::HOME ? ArmState::READY_TO_RETRACT : ArmState::RETRACT_TO_READY;
  if (state == away) return pressed ? ButtonAction::RELEASE : ButtonAction::PRESS;
  if (state == toward) return pressed ? ButtonAction::WAIT : ButtonAction::PRESS;
  switch (state) {
    case ArmState::NORMAL_TO_READY:
    case ArmState::NORMAL:
    case ArmState::NOINIT:
      if (goal == ArmGoal::RETRACT) return ButtonAction::REFUSE;  // only from HOME
      return pressed ? ButtonAction::WAIT : ButtonAction::PRESS;
    case ArmState::RETRACT_STANDBY:  // goal HOME here: the goal state was handled above
    case ArmState::READY_STANDBY:    // goal RETRACT here
      return pressed ? ButtonAction::WAIT : ButtonAction::PRESS;
    case ArmState::ERROR:
    default:
      return ButtonAction::REFUSE;
  }
}

}  // namespace orthoflow::drivers::jaco
