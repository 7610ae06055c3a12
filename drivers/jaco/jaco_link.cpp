#include "drivers/jaco/jaco_link.hpp"

#include <array>

namespace orthoflow::drivers::jaco {
namespace {

Unexpected<JacoError> usb_error(const UsbError& usb, Command command) {
  JacoError e;
  e.code = JacoError::Code::USB;
  e.usb = usb;
  e.command = command;
  return err(e);
}

Unexpected<JacoError> reply_error(PacketCheck check, Command command) {
  JacoError e;
  e.code = JacoError::Code::BAD_REPLY;
  e.check = check;
  e.command = command;
  return err(e);
}

bool is_read(Command command) noexcept {
  switch (command) {
    case Command::GET_CLIENT_INFO:
    case Command::GET_ANG_POS:
    case Command::GET_FIRMWARE:
    case Command::GET_ARM_STATUS:
    case Command::GET_CART_INFO:
    case Command::GET_ANG_INFO:
    case Command::GET_CART_COMMAND:
    case Command::GET_ANG_COMMAND:
    case Command::GET_CART_FORCE:
    case Command::GET_ANG_FORCE:
    case Command::GET_ANG_CURRENT:
    case Command::GET_SENSOR_INFO:
    case Command::GET_ANG_CURRENT_MOTOR:
    case Command::GET_ANG_VEL:
    case Command::GET_ARM_INFO:
      return true;
    default:
      return false;
  }
}

}  // namespace

const char* to_string(JacoError::Code code) noexcept {
  switch (code) {
    case JacoError::Code::USB:
      return "usb";
    case JacoError::Code::BAD_REPLY:
      return "bad_reply";
    case JacoError::Code::NO_ARM:
      return "no_arm";
    case JacoError::Code::NOT_HOMED:
      return "not_homed";
    case JacoError::Code::REFUSED:
      return "refused";
    case JacoError::Code::ESTOP:
      return "estop";
    case JacoError::Code::FAULT:
      return "fault";
    case JacoError::Code::BUSY:
      return "busy";
    case JacoError::Code::INVALID_STATE:
      return "invalid_state";
  }
  return "unknown";
}

std::string to_string(const JacoError& error) {
  std::string text = to_string(error.code);
  switch (error.code) {
    case JacoError::Code::USB:
      text += ": " + drivers::to_string(error.usb) + " during " + to_string(error.command);
      break;
    case JacoError::Code::BAD_REPLY:
      text += std::string(": ") + to_string(error.check) + " reply to " + to_string(error.command);
      break;
    case JacoError::Code::REFUSED:
      text += ": " + describe(error.violation);
      break;
    case JacoError::Code::ESTOP:
      text += ": the emergency stop is latched (orthoflow arm reset, or JacoArm::reset_estop)";
      break;
    case JacoError::Code::FAULT:
      text += ": the link to the arm failed; the arm refuses commands until it is re-initialised";
      break;
    default:
      break;
  }
  return text;
}

Result<std::vector<UsbDeviceInfo>, JacoError> list_arms(UsbTransport& transport) {
  auto found = transport.enumerate(VENDOR_KINOVA, PID_JACO);
  if (!found) return usb_error(found.error(), Command::GET_CLIENT_INFO);
  return std::move(found).value();
}

Result<JacoLink, JacoError> JacoLink::open(UsbTransport& transport, const UsbDeviceInfo& device,
                                           LinkPolicy policy) {
  auto handle = transport.open(device);
  if (!handle) return usb_error(handle.error(), Command::GET_CLIENT_INFO);
  auto claimed = transport.claim_interface(handle.value(), INTERFACE);
  if (!claimed) return usb_error(claimed.error(), Command::GET_CLIENT_INFO);
  JacoLink link(transport, std::move(handle).value(), device, policy);
  link.flush();
  return link;
}

void JacoLink::flush() noexcept {
  Packet stale{};
  for (std::uint32_t i = 0; i < policy_.flush_reads; ++i) {
    auto got = transport_->interrupt(handle_, EP_IN, stale, policy_.flush_timeout);
    if (!got || got.value() == 0) return;
    ++stats_.flushed;
  }
}

Result<void, JacoError> JacoLink::exchange_once(const Packet& request, Packet& reply) noexcept {
  const auto command = static_cast<Command>(read_header(request).command_id);
  Packet out = request;  // the transport takes a mutable span
  auto sent = transport_->interrupt(handle_, EP_OUT, out, policy_.transfer_timeout);
  if (!sent) {
    if (sent.error().code == UsbError::Code::TIMEOUT) ++stats_.timeouts;
    return usb_error(sent.error(), command);
  }
  if (sent.value() != PACKET_BYTES) {
    return usb_error({UsbError::Code::SHORT_TRANSFER, static_cast<int>(sent.value()), "interrupt"},
                     command);
  }
  reply.fill(std::byte{0});
  auto got = transport_->interrupt(handle_, EP_IN, reply, policy_.transfer_timeout);
  if (!got) {
    if (got.error().code == UsbError::Code::TIMEOUT) ++stats_.timeouts;
    return usb_error(got.error(), command);
  }
  const PacketCheck check =
      check_reply(std::span<const std::byte>(reply.data(), got.value()), command);
  if (check != PacketCheck::OK) {
    ++stats_.bad_replies;
    return reply_error(check, command);
  }
  ++stats_.exchanges;
  return {};
}

Result<void, JacoError> JacoLink::exchange(const Packet& request, Packet& reply) noexcept {
  const auto command = static_cast<Command>(read_header(request).command_id);
  const std::uint32_t attempts = is_read(command) ? policy_.retries + 1 : 1;
  Result<void, JacoError> result;
  for (std::uint32_t a = 0; a < attempts; ++a) {
    if (a > 0) ++stats_.retries;
    result = exchange_once(request, reply);
    if (result) return result;
    // An unplugged arm does not come back by asking again.
    if (result.error().code == JacoError::Code::USB &&
        result.error().usb.code == UsbError::Code::NO_DEVICE) {
      return result;
    }
  }
  return result;
}

Result<void, JacoError> JacoLink::command(Command command) noexcept {
  Packet reply{};
  return exchange(make_plain_command(command), reply);
}

Result<NineFloats, JacoError> JacoLink::read_nine(Command command) noexcept {
  Packet reply{};
  for (std::uint32_t a = 0; a <= policy_.retries; ++a) {
    auto ok = exchange(make_request(command), reply);
    if (!ok) return err(ok.error());
    NineFloats values;
    const PacketCheck check = parse_nine(reply, values);
    if (check == PacketCheck::OK) return values;
    ++stats_.bad_replies;
    if (a == policy_.retries) return reply_error(check, command);
  }
  return reply_error(PacketCheck::BAD_VALUE, command);
}

Result<ArmIdentity, JacoError> JacoLink::read_identity() noexcept {
  ArmIdentity identity;
  identity.device = device_;
  std::array<std::byte, 2 * BODY_BYTES> strings{};
  Packet reply{};
  for (std::uint16_t slice = 1; slice <= CLIENT_INFO_SLICES; ++slice) {
    auto ok = exchange(make_request(Command::GET_CLIENT_INFO, slice), reply);
    if (!ok) return err(ok.error());
    if (slice <= 2) {
      std::copy(reply.begin() + HEADER_BYTES, reply.end(),
                strings.begin() + (slice - 1) * BODY_BYTES);
    }
  }
  const PacketCheck client = parse_client_info(strings, identity.client);
  if (client != PacketCheck::OK) return reply_error(client, Command::GET_CLIENT_INFO);
  auto ok = exchange(make_request(Command::GET_FIRMWARE), reply);
  if (!ok) return err(ok.error());
  const PacketCheck firmware = parse_firmware(reply, identity.firmware);
  if (firmware != PacketCheck::OK) return reply_error(firmware, Command::GET_FIRMWARE);
  identity.model = detect_model(identity.client, identity.firmware);
  return identity;
}

Result<ArmState, JacoError> JacoLink::read_state(bool dsp5) noexcept {
  Packet reply{};
  if (dsp5) {
    auto ok = exchange(make_request(Command::GET_ARM_STATUS), reply);
    if (!ok) return err(ok.error());
    ArmStatus status;
    const PacketCheck check = parse_arm_status(reply, status);
    if (check != PacketCheck::OK) return reply_error(check, Command::GET_ARM_STATUS);
    return status.state;
  }
  ArmState state = ArmState::ERROR;
  for (std::uint16_t slice = 1; slice <= ARM_INFO_SLICES; ++slice) {
    auto ok = exchange(make_request(Command::GET_ARM_INFO, slice), reply);
    if (!ok) return err(ok.error());
    if (slice == 2) {
      const PacketCheck check = parse_arm_info_slice2(reply, state);
      if (check != PacketCheck::OK) return reply_error(check, Command::GET_ARM_INFO);
    }
  }
  return state;
}

Result<SensorInfo, JacoError> JacoLink::read_sensors() noexcept {
  Packet reply{};
  auto ok = exchange(make_request(Command::GET_SENSOR_INFO), reply);
  if (!ok) return err(ok.error());
  SensorInfo info;
  const PacketCheck check = parse_sensor_info(reply, info);
  if (check != PacketCheck::OK) return reply_error(check, Command::GET_SENSOR_INFO);
  return info;
}

}  // namespace orthoflow::drivers::jaco
