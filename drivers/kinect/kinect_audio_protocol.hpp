#pragma once
/// @file
/// @brief The protocol of the 1473 / K4W audio function as pure functions over bytes
/// (specs/KINECT_V1.md 12): the 24-byte bootloader command, the 12-byte status, the firmware image
/// header, the 20-byte motor command, the 104-byte state block, and the function's firmware state
/// from its interface count. Split out of kinect_audio.hpp, which includes it (FirmwareLoader and
/// AudioMotor use these over the USB seam). Implemented in kinect_audio_protocol.cpp.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "core/result.hpp"
#include "drivers/kinect/kinect_motor.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

// ---- The protocol, pure (KINECT_V1.md 12) -------------------------------------------------------

inline constexpr std::uint32_t AUDIO_COMMAND_MAGIC = 0x06022009;  ///< bootloader and motor commands
inline constexpr std::uint32_t AUDIO_STATUS_MAGIC = 0x0A6FE000;   ///< the 12-byte status reply
inline constexpr std::uint32_t AUDIO_FIRMWARE_MAGIC = 0xCA77F00D;  ///< the image header's magic
inline constexpr std::uint8_t AUDIO_ENDPOINT_OUT = 0x01;
inline constexpr std::uint8_t AUDIO_ENDPOINT_IN = 0x81;
inline constexpr std::size_t BOOTLOADER_COMMAND_BYTES = 24;  ///< 6 x LE u32
inline constexpr std::size_t AUDIO_STATUS_BYTES = 12;        ///< 3 x LE u32
inline constexpr std::size_t FIRMWARE_HEADER_BYTES = 24;     ///< u32, 4 x u16, 3 x u32
inline constexpr std::size_t FIRMWARE_CHUNK_BYTES = 0x4000;  ///< one write command's data at most
inline constexpr std::size_t AUDIO_BULK_PACKET_BYTES = 512;  ///< one bulk OUT write at most
/// @brief Images claiming more than this are refused as absurd (our bound, not the brief's: the
/// audio firmware is a few hundred KB).
inline constexpr std::uint32_t FIRMWARE_MAX_BYTES = 4U << 20;
inline constexpr std::uint32_t BOOTLOADER_CMD_WRITE = 0x03;
inline constexpr std::uint32_t BOOTLOADER_CMD_EXECUTE = 0x04;

inline constexpr std::uint32_t AUDIO_CMD_LED = 0x10;
inline constexpr std::uint32_t AUDIO_CMD_TILT = 0x803B;
inline constexpr std::uint32_t AUDIO_CMD_STATE = 0x8032;
inline constexpr std::uint32_t AUDIO_STATE_ARG1 = 0x68;       ///< 104, the block's length
inline constexpr std::size_t AUDIO_MOTOR_COMMAND_BYTES = 20;  ///< 5 x LE u32
inline constexpr std::size_t AUDIO_STATE_REQUEST_BYTES = 16;  ///< libfreenect omits arg2
inline constexpr std::size_t AUDIO_STATE_BLOCK_BYTES = 104;   ///< x, y, z, tilt at 16..31
inline constexpr double AUDIO_ACCEL_COUNTS_PER_G = 819.0;     ///< unconfirmed (13, row 10)
inline constexpr std::int32_t AUDIO_TILT_LIMIT_DEG = 31;      ///< refused beyond, never clipped

/// @brief One bootloader command (the magic and the trailing 0 are added by the encoder).
struct BootloaderCommand {
  std::uint32_t tag = 0;
  std::uint32_t bytes = 0;  ///< data bytes that follow (write), 0 for execute
  std::uint32_t cmd = 0;    ///< BOOTLOADER_CMD_WRITE or BOOTLOADER_CMD_EXECUTE
  std::uint32_t addr = 0;   ///< target address (write), entry address (execute)
};
/// @brief The 24 bytes: magic 0x06022009, tag, bytes, cmd, addr, 0, each LE u32. @pre none.
/// @note Pure.
[[nodiscard]] std::array<std::byte, BOOTLOADER_COMMAND_BYTES> encode_bootloader_command(
    const BootloaderCommand& command) noexcept;

/// @brief What check_audio_status found wrong.
enum class AudioStatusCheck : std::uint8_t {
  OK,
  WRONG_LENGTH,   ///< not exactly 12 bytes
  BAD_MAGIC,      ///< not 0x0A6FE000
  WRONG_TAG,      ///< not the tag sent
  DEVICE_STATUS,  ///< the status word is not 0
};
/// @brief "ok", "wrong_length", "bad_magic", "wrong_tag", "device_status". @pre none.
[[nodiscard]] const char* to_string(AudioStatusCheck check) noexcept;
/// @brief The decoded 12-byte status.
struct AudioStatus {
  std::uint32_t magic = 0;
  std::uint32_t tag = 0;
  std::uint32_t status = 0;
};
/// @brief Decodes @p reply. @return nullopt unless exactly 12 bytes. @pre none. @note Pure.
[[nodiscard]] std::optional<AudioStatus> decode_audio_status(
    std::span<const std::byte> reply) noexcept;
/// @brief Checks all three words of @p reply against tag @p tag (in that order: length, magic,
/// tag, status). @pre none. @note Pure; @p reply is untrusted device data.
[[nodiscard]] AudioStatusCheck check_audio_status(std::span<const std::byte> reply,
                                                  std::uint32_t tag) noexcept;

/// @brief The image header, the first FIRMWARE_HEADER_BYTES of the file (LE).
struct FirmwareHeader {
  std::uint32_t magic = 0;
  std::array<std::uint16_t, 4> version{};  ///< minor, major, release, patch
  std::uint32_t base_addr = 0;             ///< where byte 0 of the file goes (audio: 0x00080000)
  std::uint32_t size = 0;                  ///< bytes to upload from byte 0, header included
  std::uint32_t entry_addr = 0;            ///< the execute command's address
};
/// @brief Why an image was refused.
enum class FirmwareCheck : std::uint8_t {
  OK,
  TOO_SHORT,         ///< fewer bytes than a header
  BAD_MAGIC,         ///< not 0xCA77F00D
  SIZE_TOO_SMALL,    ///< size smaller than the header itself
  SIZE_ABSURD,       ///< size beyond FIRMWARE_MAX_BYTES, or base_addr + size wraps past 2^32
  SIZE_BEYOND_FILE,  ///< size larger than the file
};
/// @brief "ok", "too_short", "bad_magic", "size_too_small", "size_absurd", "size_beyond_file".
[[nodiscard]] const char* to_string(FirmwareCheck check) noexcept;
/// @brief Parses and validates the header of @p image (the whole file). @pre none. @note Pure.
[[nodiscard]] Result<FirmwareHeader, FirmwareCheck> parse_firmware_header(
    std::span<const std::byte> image) noexcept;
/// @brief The FIRMWARE_HEADER_BYTES of @p header, for building (synthetic) images. @note Pure.
[[nodiscard]] std::array<std::byte, FIRMWARE_HEADER_BYTES> encode_firmware_header(
    const FirmwareHeader& header) noexcept;

/// @brief One motor command on the running firmware (magic added by the encoder).
struct AudioMotorCommand {
  std::uint32_t tag = 0;
  std::uint32_t arg1 = 0;
  std::uint32_t cmd = 0;
  std::uint32_t arg2 = 0;
};
/// @brief The 20 bytes: magic, tag, arg1, cmd, arg2, each LE u32 (a state read sends the first
/// AUDIO_STATE_REQUEST_BYTES only). @pre none. @note Pure.
[[nodiscard]] std::array<std::byte, AUDIO_MOTOR_COMMAND_BYTES> encode_audio_motor_command(
    const AudioMotorCommand& command) noexcept;
/// @brief arg2 of the LED command: OFF 1, BLINK_GREEN 2, GREEN 3, RED 4; YELLOW 3 (green, as
/// libfreenect maps it: the firmware has no yellow); BLINK_RED_YELLOW 2 (blink green: our choice by
/// the same rule, not in the brief). @pre none. @note Pure.
[[nodiscard]] std::uint32_t audio_led_code(LedMode mode) noexcept;
/// @brief arg2 of the tilt command: signed whole degrees (not doubled), rounded to the nearest,
/// halves away from zero, as two's complement. @return nullopt if @p degrees is not finite or
/// beyond +-AUDIO_TILT_LIMIT_DEG (refused, never clipped). @pre none. @note Pure.
[[nodiscard]] std::optional<std::uint32_t> encode_audio_tilt(double degrees) noexcept;

/// @brief The decoded 104-byte state block.
struct AudioMotorState {
  std::array<std::int32_t, 3> accel_counts{};  ///< x, y, z: LE int32 at 16, 20, 24
  std::array<double, 3> accel_g{};             ///< counts / 819 (unconfirmed, 13 row 10)
  std::array<double, 3> accel_mps2{};          ///< accel_g x 9.80665
  std::int32_t tilt_deg = 0;                   ///< LE int32 at 28, whole degrees
};
/// @brief Decodes a state block. @return nullopt unless exactly 104 bytes. @pre none. @note Pure;
/// every value is accepted (untrusted device data).
[[nodiscard]] std::optional<AudioMotorState> decode_audio_motor_state(
    std::span<const std::byte> block) noexcept;
/// @brief The same reading in the 1414's MotorState: tilt_raw = 2 x degrees (libfreenect's
/// half-degree convention; TILT_RAW_NO_READING if it does not fit an int8), accel_counts saturated
/// to int16 (accel_g and accel_mps2 keep the full value). The block carries no motion status:
/// status is UNKNOWN, status_raw 0. @pre none. @note Pure.
[[nodiscard]] MotorState to_motor_state(const AudioMotorState& state) noexcept;

/// @brief The audio function's state, from its interface count (KINECT_V1.md 12.1).
enum class AudioFirmware : std::uint8_t {
  UNKNOWN,     ///< interface_count 0: unreadable
  BOOTLOADER,  ///< one interface: firmware not loaded
  RUNNING,     ///< two or more: firmware running
};
/// @brief The state of @p audio. @pre none. @note Pure.
[[nodiscard]] AudioFirmware audio_firmware_state(const UsbDeviceInfo& audio) noexcept;
/// @brief True for the audio PIDs: 0x02AD (1414/1473), 0x02BE, 0x02C3, 0x02BB (K4W). @note Pure.
[[nodiscard]] bool is_audio_pid(std::uint16_t product) noexcept;

}  // namespace orthoflow::drivers::kinect
