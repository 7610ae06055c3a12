// AudioMotor (kinect_audio.hpp): tilt, LED and accelerometer of a 1473 / K4W through its running
// audio firmware, bulk commands on 0x01 and replies on 0x81, each checked before use.
#include "drivers/kinect/kinect_audio.hpp"

#include <algorithm>

#include "drivers/kinect/kinect_protocol.hpp"

namespace orthoflow::drivers::kinect {

namespace {

KinectError kinect_usb(const UsbError& usb, std::uint16_t opcode = 0) noexcept {
  KinectError e;
  e.code = KinectError::Code::USB;
  e.usb = usb;
  e.opcode = opcode;
  return e;
}

}  // namespace

// ---- AudioMotor ---------------------------------------------------------------------------------

AudioMotor::AudioMotor(UsbTransport& transport, UsbDeviceHandle handle, const UsbDeviceInfo& info,
                       AudioMotorOptions options) noexcept
    : transport_(&transport), handle_(std::move(handle)), info_(info), options_(options) {}

Result<std::unique_ptr<AudioMotor>, KinectError> AudioMotor::open(UsbTransport& transport,
                                                                  const CameraInfo& camera,
                                                                  AudioMotorOptions options) {
  if (camera.model == Model::K1414)
    return err(kinect_usb(UsbError{UsbError::Code::NOT_SUPPORTED, 0,
                                   "kinect audio motor: a 1414 has a motor function (0x02B0)"}));
  if (options.command_timeout.count() <= 0 || options.reply_timeout.count() <= 0)
    return err(kinect_usb(
        UsbError{UsbError::Code::INVALID_PARAM, 0, "kinect audio motor: timeouts must be > 0"}));
  FirmwareLoader finder(transport);
  auto audio = finder.find_audio(camera);
  if (!audio) {
    if (audio.error().code == FirmwareError::Code::USB) return err(kinect_usb(audio.error().usb));
    return err(kinect_usb(UsbError{UsbError::Code::NOT_FOUND, 0,
                                   "kinect audio motor: no audio sibling of the camera"}));
  }
  if (audio_firmware_state(audio.value()) != AudioFirmware::RUNNING)
    return err(kinect_usb(UsbError{
        UsbError::Code::NOT_SUPPORTED, 0,
        "kinect motor: 1473/K4W audio firmware not running; upload the audio firmware first "
        "(orthoflow kinect firmware --file audios.bin)"}));
  auto opened = transport.open(audio.value());
  if (!opened) return err(kinect_usb(opened.error()));
  UsbDeviceHandle handle = std::move(opened.value());
  if (options.reset_at_open) {
    if (auto r = transport.reset_device(handle); !r) return err(kinect_usb(r.error()));
  }
  if (auto c = transport.claim_interface(handle, 0); !c) return err(kinect_usb(c.error()));
  return std::unique_ptr<AudioMotor>(
      new AudioMotor(transport, std::move(handle), audio.value(), options));
}

Result<std::size_t, KinectError> AudioMotor::exchange(const AudioMotorCommand& command,
                                                      std::size_t command_bytes,
                                                      std::span<std::byte> block) {
  auto frame = encode_audio_motor_command(command);
  ++tag_;  // per command sent, whatever the outcome
  const auto opcode = static_cast<std::uint16_t>(command.cmd);
  const auto failed = [&](const UsbError& usb) {
    ++stats_.failures;
    if (usb.code == UsbError::Code::TIMEOUT) ++stats_.timeouts;
    return kinect_usb(usb, opcode);
  };
  auto sent =
      transport_->bulk(handle_, AUDIO_ENDPOINT_OUT,
                       std::span<std::byte>(frame.data(), command_bytes), options_.command_timeout);
  if (!sent) return err(failed(sent.error()));
  std::size_t block_bytes = 0;
  if (!block.empty()) {
    auto got = transport_->bulk(handle_, AUDIO_ENDPOINT_IN, block, options_.reply_timeout);
    if (!got) return err(failed(got.error()));
    block_bytes = got.value();
  }
  std::array<std::byte, AUDIO_STATUS_BYTES + 4> reply{};
  auto got = transport_->bulk(handle_, AUDIO_ENDPOINT_IN, reply, options_.reply_timeout);
  if (!got) return err(failed(got.error()));
  const std::span<const std::byte> status(reply.data(), got.value());
  const AudioStatusCheck check = check_audio_status(status, command.tag);
  if (check != AudioStatusCheck::OK) {
    ++stats_.failures;
    KinectError e;
    e.opcode = opcode;
    if (check == AudioStatusCheck::DEVICE_STATUS) {
      e.code = KinectError::Code::DEVICE_STATUS;
      e.status = static_cast<std::uint16_t>(
          std::min<std::uint32_t>(decode_audio_status(status)->status, 0xFFFF));
    } else {
      ++stats_.bad_replies;
      e.code = KinectError::Code::BAD_REPLY;
      e.reply = check == AudioStatusCheck::BAD_MAGIC   ? ReplyCheck::BAD_MAGIC
                : check == AudioStatusCheck::WRONG_TAG ? ReplyCheck::WRONG_TAG
                                                       : ReplyCheck::BAD_LENGTH;
    }
    return err(e);
  }
  ++stats_.commands;
  return block_bytes;
}

Result<void, KinectError> AudioMotor::set_tilt(double degrees) {
  const auto maybe_arg = encode_audio_tilt(degrees);
  if (!maybe_arg) {
    KinectError e;
    e.code = KinectError::Code::INVALID_ARGUMENT;
    e.opcode = static_cast<std::uint16_t>(AUDIO_CMD_TILT);
    return err(e);
  }
  auto done = exchange({tag_, 0, AUDIO_CMD_TILT, *maybe_arg}, AUDIO_MOTOR_COMMAND_BYTES, {});
  if (!done) return err(done.error());
  return {};
}

Result<void, KinectError> AudioMotor::set_led(LedMode mode) {
  auto done =
      exchange({tag_, 0, AUDIO_CMD_LED, audio_led_code(mode)}, AUDIO_MOTOR_COMMAND_BYTES, {});
  if (!done) return err(done.error());
  return {};
}

Result<AudioMotorState, KinectError> AudioMotor::read_state() {
  std::array<std::byte, AUDIO_STATE_BLOCK_BYTES + 4> block{};  // room to see an over-long block
  auto got =
      exchange({tag_, AUDIO_STATE_ARG1, AUDIO_CMD_STATE, 0}, AUDIO_STATE_REQUEST_BYTES, block);
  if (!got) return err(got.error());
  auto maybe_state =
      decode_audio_motor_state(std::span<const std::byte>(block.data(), got.value()));
  if (!maybe_state) {
    ++stats_.bad_replies;
    KinectError e;
    e.code = KinectError::Code::BAD_REPLY;
    e.reply = ReplyCheck::BAD_LENGTH;
    e.opcode = static_cast<std::uint16_t>(AUDIO_CMD_STATE);
    return err(e);
  }
  return *maybe_state;
}

}  // namespace orthoflow::drivers::kinect
