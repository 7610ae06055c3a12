// The JACO's packet framing (jaco_protocol.hpp, JACO.md 3-5): command names, the header, typed
// access to the body, the reply check; then model detection (JACO.md 8) and the HOME / RETRACT
// button table (JACO.md 10.1). The payload codecs are in jaco_payloads.cpp.
#include "drivers/jaco/jaco_protocol.hpp"

#include <algorithm>
#include <cstring>

#include "core/assert.hpp"
#include "drivers/jaco/jaco_packet_bytes.hpp"

namespace orthoflow::drivers::jaco {
namespace {

using detail::body_offset;
using detail::load_u16;
using detail::load_u32;
using detail::store_u16;
using detail::store_u32;

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
