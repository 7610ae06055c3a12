// The pure protocol of the 1473 / K4W audio function (kinect_audio_protocol.hpp): encoders and
// decoders of its bootloader commands, status, image header, motor commands and state block, all
// little-endian, plus the firmware state and the audio PIDs.
#include "drivers/kinect/kinect_audio_protocol.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace orthoflow::drivers::kinect {

namespace {

constexpr std::array<std::uint16_t, 4> AUDIO_PIDS = {0x02AD, 0x02BE, 0x02C3, 0x02BB};

void put_u32(std::span<std::byte> out, std::size_t at, std::uint32_t v) noexcept {
  for (std::size_t i = 0; i < 4; ++i)
    out[at + i] = std::byte{static_cast<std::uint8_t>(v >> (8 * i))};
}

void put_u16(std::span<std::byte> out, std::size_t at, std::uint16_t v) noexcept {
  out[at] = std::byte{static_cast<std::uint8_t>(v & 0xFFU)};
  out[at + 1] = std::byte{static_cast<std::uint8_t>(v >> 8)};
}

std::uint32_t get_u32(std::span<const std::byte> in, std::size_t at) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= std::to_integer<std::uint32_t>(in[at + i]) << (8 * i);
  return v;
}

std::uint16_t get_u16(std::span<const std::byte> in, std::size_t at) noexcept {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(in[at]) |
                                    (std::to_integer<unsigned>(in[at + 1]) << 8));
}

}  // namespace

// ---- Codecs -------------------------------------------------------------------------------------

std::array<std::byte, BOOTLOADER_COMMAND_BYTES> encode_bootloader_command(
    const BootloaderCommand& command) noexcept {
  std::array<std::byte, BOOTLOADER_COMMAND_BYTES> out{};
  put_u32(out, 0, AUDIO_COMMAND_MAGIC);
  put_u32(out, 4, command.tag);
  put_u32(out, 8, command.bytes);
  put_u32(out, 12, command.cmd);
  put_u32(out, 16, command.addr);
  put_u32(out, 20, 0);
  return out;
}

const char* to_string(AudioStatusCheck check) noexcept {
  switch (check) {
    case AudioStatusCheck::OK:
      return "ok";
    case AudioStatusCheck::WRONG_LENGTH:
      return "wrong_length";
    case AudioStatusCheck::BAD_MAGIC:
      return "bad_magic";
    case AudioStatusCheck::WRONG_TAG:
      return "wrong_tag";
    case AudioStatusCheck::DEVICE_STATUS:
      return "device_status";
  }
  return "unknown";
}

std::optional<AudioStatus> decode_audio_status(std::span<const std::byte> reply) noexcept {
  if (reply.size() != AUDIO_STATUS_BYTES) return std::nullopt;
  return AudioStatus{get_u32(reply, 0), get_u32(reply, 4), get_u32(reply, 8)};
}

AudioStatusCheck check_audio_status(std::span<const std::byte> reply, std::uint32_t tag) noexcept {
  const auto maybe_status = decode_audio_status(reply);
  if (!maybe_status) return AudioStatusCheck::WRONG_LENGTH;
  if (maybe_status->magic != AUDIO_STATUS_MAGIC) return AudioStatusCheck::BAD_MAGIC;
  if (maybe_status->tag != tag) return AudioStatusCheck::WRONG_TAG;
  if (maybe_status->status != 0) return AudioStatusCheck::DEVICE_STATUS;
  return AudioStatusCheck::OK;
}

const char* to_string(FirmwareCheck check) noexcept {
  switch (check) {
    case FirmwareCheck::OK:
      return "ok";
    case FirmwareCheck::TOO_SHORT:
      return "too_short";
    case FirmwareCheck::BAD_MAGIC:
      return "bad_magic";
    case FirmwareCheck::SIZE_TOO_SMALL:
      return "size_too_small";
    case FirmwareCheck::SIZE_ABSURD:
      return "size_absurd";
    case FirmwareCheck::SIZE_BEYOND_FILE:
      return "size_beyond_file";
  }
  return "unknown";
}

Result<FirmwareHeader, FirmwareCheck> parse_firmware_header(
    std::span<const std::byte> image) noexcept {
  if (image.size() < FIRMWARE_HEADER_BYTES) return err(FirmwareCheck::TOO_SHORT);
  FirmwareHeader h;
  h.magic = get_u32(image, 0);
  for (std::size_t i = 0; i < 4; ++i) h.version[i] = get_u16(image, 4 + 2 * i);
  h.base_addr = get_u32(image, 12);
  h.size = get_u32(image, 16);
  h.entry_addr = get_u32(image, 20);
  if (h.magic != AUDIO_FIRMWARE_MAGIC) return err(FirmwareCheck::BAD_MAGIC);
  if (h.size < FIRMWARE_HEADER_BYTES) return err(FirmwareCheck::SIZE_TOO_SMALL);
  if (h.size > FIRMWARE_MAX_BYTES || std::uint64_t{h.base_addr} + h.size >
                                         std::uint64_t{std::numeric_limits<std::uint32_t>::max()})
    return err(FirmwareCheck::SIZE_ABSURD);
  if (h.size > image.size()) return err(FirmwareCheck::SIZE_BEYOND_FILE);
  return h;
}

std::array<std::byte, FIRMWARE_HEADER_BYTES> encode_firmware_header(
    const FirmwareHeader& header) noexcept {
  std::array<std::byte, FIRMWARE_HEADER_BYTES> out{};
  put_u32(out, 0, header.magic);
  for (std::size_t i = 0; i < 4; ++i) put_u16(out, 4 + 2 * i, header.version[i]);
  put_u32(out, 12, header.base_addr);
  put_u32(out, 16, header.size);
  put_u32(out, 20, header.entry_addr);
  return out;
}

std::array<std::byte, AUDIO_MOTOR_COMMAND_BYTES> encode_audio_motor_command(
    const AudioMotorCommand& command) noexcept {
  std::array<std::byte, AUDIO_MOTOR_COMMAND_BYTES> out{};
  put_u32(out, 0, AUDIO_COMMAND_MAGIC);
  put_u32(out, 4, command.tag);
  put_u32(out, 8, command.arg1);
  put_u32(out, 12, command.cmd);
  put_u32(out, 16, command.arg2);
  return out;
}

std::uint32_t audio_led_code(LedMode mode) noexcept {
  switch (mode) {
    case LedMode::OFF:
      return 1;
    case LedMode::BLINK_GREEN:
    case LedMode::BLINK_RED_YELLOW:
      return 2;
    case LedMode::GREEN:
    case LedMode::YELLOW:
      return 3;
    case LedMode::RED:
      return 4;
  }
  return 1;
}

std::optional<std::uint32_t> encode_audio_tilt(double degrees) noexcept {
  if (!std::isfinite(degrees) || std::abs(degrees) > AUDIO_TILT_LIMIT_DEG) return std::nullopt;
  const auto whole = static_cast<std::int32_t>(std::lround(degrees));
  return static_cast<std::uint32_t>(whole);
}

std::optional<AudioMotorState> decode_audio_motor_state(std::span<const std::byte> block) noexcept {
  if (block.size() != AUDIO_STATE_BLOCK_BYTES) return std::nullopt;
  AudioMotorState s;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    s.accel_counts[axis] = static_cast<std::int32_t>(get_u32(block, 16 + 4 * axis));
    s.accel_g[axis] = static_cast<double>(s.accel_counts[axis]) / AUDIO_ACCEL_COUNTS_PER_G;
    s.accel_mps2[axis] = s.accel_g[axis] * STANDARD_GRAVITY_MPS2;
  }
  s.tilt_deg = static_cast<std::int32_t>(get_u32(block, 28));
  return s;
}

MotorState to_motor_state(const AudioMotorState& state) noexcept {
  MotorState m;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    m.accel_counts[axis] = static_cast<std::int16_t>(
        std::clamp<std::int32_t>(state.accel_counts[axis], std::numeric_limits<std::int16_t>::min(),
                                 std::numeric_limits<std::int16_t>::max()));
    m.accel_g[axis] = state.accel_g[axis];
    m.accel_mps2[axis] = state.accel_mps2[axis];
  }
  m.tilt_deg = static_cast<double>(state.tilt_deg);
  const std::int64_t half = std::int64_t{state.tilt_deg} * 2;
  m.tilt_raw = half > -128 && half <= 127 ? static_cast<std::int8_t>(half) : TILT_RAW_NO_READING;
  m.status = TiltStatus::UNKNOWN;
  m.status_raw = 0;
  return m;
}

AudioFirmware audio_firmware_state(const UsbDeviceInfo& audio) noexcept {
  if (audio.interface_count == 0) return AudioFirmware::UNKNOWN;
  return audio.interface_count >= 2 ? AudioFirmware::RUNNING : AudioFirmware::BOOTLOADER;
}

bool is_audio_pid(std::uint16_t product) noexcept {
  return std::find(AUDIO_PIDS.begin(), AUDIO_PIDS.end(), product) != AUDIO_PIDS.end();
}

}  // namespace orthoflow::drivers::kinect
