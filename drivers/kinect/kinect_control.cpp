#include "drivers/kinect/kinect_control.hpp"

#include <array>
#include <cstdio>
#include <cstring>

namespace orthoflow::drivers::kinect {

const char* to_string(KinectError::Code code) noexcept {
  switch (code) {
    case KinectError::Code::USB:
      return "usb";
    case KinectError::Code::BAD_REPLY:
      return "bad_reply";
    case KinectError::Code::NOT_READY:
      return "not_ready";
    case KinectError::Code::DEVICE_STATUS:
      return "device_status";
    case KinectError::Code::BAD_CALIBRATION:
      return "bad_calibration";
    case KinectError::Code::REPLY_TOO_LONG:
      return "reply_too_long";
    case KinectError::Code::NO_CAMERA:
      return "no_camera";
    case KinectError::Code::INVALID_ARGUMENT:
      return "invalid_argument";
    case KinectError::Code::STALLED:
      return "stalled";
  }
  return "unknown";
}

std::string to_string(const KinectError& error) {
  std::string text = to_string(error.code);
  char opcode[32];
  std::snprintf(opcode, sizeof opcode, ": opcode 0x%02x", static_cast<unsigned>(error.opcode));
  switch (error.code) {
    case KinectError::Code::USB:
      return text + opcode + ", " + to_string(error.usb);
    case KinectError::Code::BAD_REPLY:
      return text + opcode + ", " + to_string(error.reply);
    case KinectError::Code::DEVICE_STATUS:
      return text + opcode + ", status " + std::to_string(error.status);
    case KinectError::Code::BAD_CALIBRATION:
      return text + opcode + ", " + to_string(error.parse);
    case KinectError::Code::NOT_READY:
    case KinectError::Code::REPLY_TOO_LONG:
      return text + opcode;
    default:
      return text;
  }
}

namespace {

constexpr UsbControlSetup COMMAND_OUT{0x40, 0x00, 0, 0};
constexpr UsbControlSetup REPLY_IN{0xC0, 0x00, 0, 0};

KinectError usb_failure(std::uint16_t opcode, const UsbError& usb) noexcept {
  KinectError e;
  e.code = KinectError::Code::USB;
  e.usb = usb;
  e.opcode = opcode;
  return e;
}

}  // namespace

Result<std::size_t, KinectError> KinectControl::attempt(std::uint16_t opcode,
                                                        std::span<const std::byte> frame,
                                                        std::span<std::byte> reply,
                                                        std::int64_t deadline_ns) {
  // The command buffer is const for the caller; libusb's OUT transfer does not write it.
  std::array<std::byte, HEADER_BYTES + MAX_COMMAND_PAYLOAD> out{};
  std::memcpy(out.data(), frame.data(), frame.size());
  auto sent = transport_->control(*camera_, COMMAND_OUT, std::span(out.data(), frame.size()),
                                  policy_.transfer_timeout);
  if (!sent.has_value()) {
    if (sent.error().code == UsbError::Code::TIMEOUT) ++stats_.timeouts;
    return err(usb_failure(opcode, sent.error()));
  }
  std::array<std::byte, REPLY_BUFFER_BYTES> in{};
  KinectError last;
  last.code = KinectError::Code::NOT_READY;
  last.opcode = opcode;
  for (std::uint32_t poll = 0;
       poll < policy_.max_polls && transport_->clock().now_ns() < deadline_ns; ++poll) {
    auto got = transport_->control(*camera_, REPLY_IN, in, policy_.transfer_timeout);
    if (!got.has_value()) {
      if (got.error().code == UsbError::Code::TIMEOUT) {
        ++stats_.timeouts;
        last = usb_failure(opcode, got.error());
        continue;  // the next read may still find the reply
      }
      return err(usb_failure(opcode, got.error()));
    }
    const Reply r = check_reply(std::span<const std::byte>(in.data(), got.value()), opcode, tag_);
    if (r.check == ReplyCheck::NOT_READY) {
      ++stats_.not_ready_polls;
      continue;
    }
    if (r.check != ReplyCheck::OK) {
      ++stats_.bad_replies;
      KinectError e;
      e.code = KinectError::Code::BAD_REPLY;
      e.reply = r.check;
      e.opcode = opcode;
      return err(e);
    }
    if (r.payload.size() > reply.size()) {
      KinectError e;
      e.code = KinectError::Code::REPLY_TOO_LONG;
      e.opcode = opcode;
      return err(e);
    }
    if (!r.payload.empty()) std::memcpy(reply.data(), r.payload.data(), r.payload.size());
    return r.payload.size();
  }
  return err(last);
}

Result<std::size_t, KinectError> KinectControl::command(std::uint16_t opcode,
                                                        std::span<const std::byte> payload,
                                                        std::span<std::byte> reply) {
  const auto frame = encode_command(opcode, tag_, payload);
  if (!frame.has_value()) {
    KinectError e;
    e.code = KinectError::Code::INVALID_ARGUMENT;
    e.opcode = opcode;
    return err(e);
  }
  KinectError last;
  const std::int64_t deadline_ns =
      transport_->clock().now_ns() +
      std::chrono::duration_cast<std::chrono::nanoseconds>(policy_.command_deadline).count();
  for (std::uint32_t attempt_no = 0;
       attempt_no <= policy_.retries &&
       (attempt_no == 0 || transport_->clock().now_ns() < deadline_ns);
       ++attempt_no) {
    if (attempt_no > 0) ++stats_.retries;
    auto done = attempt(opcode, frame->view(), reply, deadline_ns);
    if (done.has_value()) {
      ++stats_.commands;
      tag_ = static_cast<std::uint16_t>(tag_ + 1);  // wraps at 16 bits, as the device expects
      return done.value();
    }
    last = done.error();
    // An unplugged device, a refused request or a caller error will not get better by resending.
    if (last.code == KinectError::Code::USB && last.usb.code != UsbError::Code::TIMEOUT &&
        last.usb.code != UsbError::Code::PIPE && last.usb.code != UsbError::Code::IO) {
      break;
    }
    if (last.code == KinectError::Code::REPLY_TOO_LONG) break;
  }
  ++stats_.failures;
  return err(last);
}

Result<void, KinectError> KinectControl::write_register(std::uint16_t reg, std::uint16_t value) {
  std::array<std::byte, 4> payload{};
  store_le16(payload, 0, reg);
  store_le16(payload, 2, value);
  std::array<std::byte, REPLY_BUFFER_BYTES> reply{};
  auto got = command(static_cast<std::uint16_t>(Opcode::SET_PARAM), payload, reply);
  if (!got.has_value()) return err(got.error());
  const std::span<const std::byte> r(reply.data(), got.value());
  if (r.size() != 2 || load_le16(r, 0) != 0) {
    ++stats_.device_statuses;
    KinectError e;
    e.code = KinectError::Code::DEVICE_STATUS;
    e.opcode = static_cast<std::uint16_t>(Opcode::SET_PARAM);
    e.status = r.size() >= 2 ? load_le16(r, 0) : 0xFFFF;
    return err(e);
  }
  return {};
}

Result<std::uint16_t, KinectError> KinectControl::read_register(std::uint16_t reg) {
  std::array<std::byte, 2> payload{};
  store_le16(payload, 0, reg);
  std::array<std::byte, REPLY_BUFFER_BYTES> reply{};
  auto got = command(static_cast<std::uint16_t>(Opcode::GET_PARAM), payload, reply);
  if (!got.has_value()) return err(got.error());
  const std::span<const std::byte> r(reply.data(), got.value());
  if (r.size() != 4 || load_le16(r, 0) != 0) {
    ++stats_.device_statuses;
    KinectError e;
    e.code = KinectError::Code::DEVICE_STATUS;
    e.opcode = static_cast<std::uint16_t>(Opcode::GET_PARAM);
    e.status = r.size() >= 2 ? load_le16(r, 0) : 0xFFFF;
    return err(e);
  }
  return load_le16(r, 2);
}

Result<void, KinectError> KinectControl::run(RegisterScript script) {
  for (const RegisterWrite& w : script) {
    if (w.wait_ms > 0) {
      const std::int64_t until = transport_->clock().now_ns() + std::int64_t{w.wait_ms} * 1'000'000;
      // Bounded: each pass waits up to the remaining time; a transport whose clock never moves
      // would be a broken transport, so the loop is also capped.
      for (int pass = 0; pass < 1000 && transport_->clock().now_ns() < until; ++pass) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            std::chrono::nanoseconds(until - transport_->clock().now_ns()));
        auto pumped = transport_->handle_events(std::max(left, UsbTimeout(1)));
        if (!pumped.has_value()) return err(usb_failure(0, pumped.error()));
      }
    }
    auto done = write_register(w.reg, w.value);
    if (!done.has_value()) return done;
  }
  return {};
}

Result<std::size_t, KinectError> KinectControl::algorithm_param(std::uint16_t param_id,
                                                                std::uint16_t resolution,
                                                                std::span<std::byte> reply) {
  std::array<std::byte, 10> payload{};
  store_le16(payload, 0, param_id);
  store_le16(payload, 2, 0);  // format
  store_le16(payload, 4, resolution);
  store_le16(payload, 6, 30);  // fps
  store_le16(payload, 8, 0);   // offset
  return command(static_cast<std::uint16_t>(Opcode::ALGORITHM_PARAMS), payload, reply);
}

Result<Calibration, KinectError> KinectControl::read_calibration(Model model) {
  Calibration cal;
  std::array<std::byte, REPLY_BUFFER_BYTES> reply{};
  auto refuse = [](std::uint16_t opcode, ParseCheck check) {
    KinectError e;
    e.code = KinectError::Code::BAD_CALIBRATION;
    e.opcode = opcode;
    e.parse = check;
    return e;
  };
  constexpr auto ALGO = static_cast<std::uint16_t>(Opcode::ALGORITHM_PARAMS);
  auto pad = algorithm_param(0x41, 1, reply);
  if (!pad.has_value()) return err(pad.error());
  if (const auto c = parse_pad_info(std::span(reply.data(), pad.value()), cal.pad);
      c != ParseCheck::OK) {
    return err(refuse(ALGO, c));
  }
  const std::array<std::byte, 10> zeros{};
  constexpr auto FIXED = static_cast<std::uint16_t>(Opcode::GET_FIXED_PARAMS);
  auto fixed = command(FIXED, zeros, reply);
  if (!fixed.has_value()) return err(fixed.error());
  if (const auto c = parse_fixed_params(std::span(reply.data(), fixed.value()), model,
                                        cal.zero_plane, cal.reported_rcmos_dist_cm);
      c != ParseCheck::OK) {
    return err(refuse(FIXED, c));
  }
  auto reg = algorithm_param(0x40, 1, reply);
  if (!reg.has_value()) return err(reg.error());
  if (const auto c = parse_reg_info(std::span(reply.data(), reg.value()), cal.reg);
      c != ParseCheck::OK) {
    return err(refuse(ALGO, c));
  }
  auto shift = algorithm_param(0x00, 1, reply);
  if (!shift.has_value()) return err(shift.error());
  if (const auto c = parse_const_shift(std::span(reply.data(), shift.value()), cal.const_shift);
      c != ParseCheck::OK) {
    return err(refuse(ALGO, c));
  }
  return cal;
}

}  // namespace orthoflow::drivers::kinect
