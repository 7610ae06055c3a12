#pragma once
/// @file
/// @brief Models 1473 and K4W: the audio function's firmware upload and the motor, LED and
/// accelerometer through the running audio firmware (specs/KINECT_V1.md 12). First the protocol as
/// pure functions over bytes (the 24-byte bootloader command, the 12-byte status, the firmware
/// image header, the 20-byte motor command, the 104-byte state block), then FirmwareLoader and
/// AudioMotor over the USB seam. Bulk transfers on EP 0x01 (OUT) and 0x81 (IN), each with a
/// finite timeout.
///
/// The firmware file (`audios.bin`, extracted from an Xbox 360 system update) is not
/// redistributable: it is never committed. The caller names the file (firmware_search_paths()
/// gives libfreenect's search order); tests build a synthetic image with a valid header.
///
/// Open questions kept visible (KINECT_V1.md 13):
/// - row 9: resetting the audio device at open (libfreenect does it to avoid hangs; issue #543 says
///   removing it helped): optional, off by default (FirmwareLoaderOptions / AudioMotorOptions
///   reset_at_open).
/// - row 10: the 1473 accelerometer scale. AUDIO_ACCEL_COUNTS_PER_G = 819 is what libfreenect
///   applies; its own comment says the units are still to be worked out. Unconfirmed: calibrate
///   against gravity before trusting accel_g.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"
#include "drivers/kinect_camera.hpp"
#include "drivers/kinect_control.hpp"
#include "drivers/kinect_motor.hpp"
#include "drivers/usb_transport.hpp"

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

// ---- The firmware file --------------------------------------------------------------------------

/// @brief Directories to look for `audios.bin` in, libfreenect's order: $LIBFREENECT_FIRMWARE_PATH
/// (if set), ".", "~/.libfreenect" (if $HOME is set), "/usr/local/share/libfreenect",
/// "/usr/share/libfreenect". @note Allocates; reads the environment.
[[nodiscard]] std::vector<std::string> firmware_search_paths();
inline constexpr std::string_view AUDIO_FIRMWARE_FILE = "audios.bin";

// ---- The loader over the seam -------------------------------------------------------------------

/// @brief Why the firmware upload failed. Copyable; the file name is kept only by the caller.
struct FirmwareError {
  enum class Code : std::uint8_t {
    USB,               ///< a transfer or open failed: see usb (and tag, cmd, chunk)
    NO_AUDIO_DEVICE,   ///< no audio sibling of the camera (or ambiguous)
    BAD_IMAGE,         ///< the image was refused: see image
    BAD_STATUS,        ///< a status reply was malformed: see status_check (and tag, chunk)
    DEVICE_STATUS,     ///< the bootloader answered a nonzero status: see status (and chunk)
    NO_REENUMERATION,  ///< the device did not come back after execute within the tries
    NOT_RUNNING,       ///< it came back with fewer than two interfaces
    FILE_UNREADABLE,   ///< the firmware file could not be read
  };
  Code code = Code::USB;
  UsbError usb{};
  FirmwareCheck image = FirmwareCheck::OK;
  AudioStatusCheck status_check = AudioStatusCheck::OK;
  std::uint32_t status = 0;  ///< the device's status word (DEVICE_STATUS)
  std::uint32_t tag = 0;     ///< of the failing command
  std::uint32_t cmd = 0;     ///< of the failing command (3 write, 4 execute)
  std::size_t chunk = 0;     ///< index of the failing chunk (writes)
};
/// @brief Lower-case name of @p code, e.g. "device_status". @pre none.
[[nodiscard]] const char* to_string(FirmwareError::Code code) noexcept;
/// @brief One line, e.g. "device_status: cmd 3, chunk 1, tag 1, status 5". @note Allocates.
[[nodiscard]] std::string to_string(const FirmwareError& error);

/// @brief Reads the whole of @p path. @return FILE_UNREADABLE if it cannot be opened or read.
/// @note Allocates; does file I/O (start-up only).
[[nodiscard]] Result<std::vector<std::byte>, FirmwareError> read_firmware_file(
    const std::string& path);

/// @brief How patient the loader is. Plain data with defaults.
struct FirmwareLoaderOptions {
  UsbTimeout transfer_timeout{250};       ///< per bulk transfer; never 0 (infinite)
  std::uint32_t reenumerate_tries = 10;   ///< enumerations looking for the serial after execute
  UsbTimeout reenumerate_interval{1000};  ///< between them, on the transport's clock
  bool reset_at_open = false;             ///< port-reset the bootloader first (13, row 9)
};

/// @brief Counters of one upload (STYLE rule 16).
struct FirmwareUploadStats {
  std::uint64_t commands = 0;      ///< bootloader commands sent (writes and the execute)
  std::uint64_t chunks = 0;        ///< write commands acknowledged
  std::uint64_t bulk_writes = 0;   ///< data bulk OUT transfers
  std::uint64_t bytes = 0;         ///< image bytes sent
  std::uint64_t enumerations = 0;  ///< enumerations made waiting for the re-enumeration
};

/// @brief Uploads the audio firmware of a 1473 / K4W and waits for the device to come back.
/// @note Belongs to the transport's thread. Allocates only for enumerations.
class FirmwareLoader {
 public:
  /// @pre @p transport outlives the loader.
  explicit FirmwareLoader(UsbTransport& transport, FirmwareLoaderOptions options = {}) noexcept
      : transport_(&transport), options_(options) {}

  /// @brief The audio sibling of @p camera (find_sibling: same hub, else same bus, else the only
  /// one). @return NO_AUDIO_DEVICE if none matches; USB errors of enumerate.
  [[nodiscard]] Result<UsbDeviceInfo, FirmwareError> find_audio(const CameraInfo& camera);
  /// @brief Uploads @p image to @p audio unless its firmware already runs (then returns it as is).
  /// Validates the header first (BAD_IMAGE, nothing sent). Opens the device (optionally resets
  /// it), claims interface 0, sends the file from byte 0 in chunks of <= 0x4000 (write command,
  /// bulk OUT writes of <= 512, status), then execute and its status. Then enumerates by serial
  /// every reenumerate_interval, pumping events in between, at most reenumerate_tries times;
  /// reopens the device found, claims interface 0 and checks >= 2 interfaces.
  /// @return the re-enumerated device (the handle is closed again); DEVICE_STATUS / BAD_STATUS
  /// naming the chunk and tag; NO_REENUMERATION; NOT_RUNNING; USB errors.
  [[nodiscard]] Result<UsbDeviceInfo, FirmwareError> upload(const UsbDeviceInfo& audio,
                                                            std::span<const std::byte> image);
  /// @brief The counters of the last upload. @pre none.
  [[nodiscard]] const FirmwareUploadStats& stats() const noexcept { return stats_; }

 private:
  [[nodiscard]] Result<void, FirmwareError> command(const UsbDeviceHandle& handle,
                                                    const BootloaderCommand& cmd,
                                                    std::span<const std::byte> data,
                                                    std::size_t chunk);
  [[nodiscard]] Result<UsbDeviceInfo, FirmwareError> wait_for_reenumeration(
      const UsbDeviceInfo& audio);

  UsbTransport* transport_;
  FirmwareLoaderOptions options_;
  FirmwareUploadStats stats_{};
};

// ---- The motor through the running firmware -----------------------------------------------------

/// @brief How patient the audio motor is (libfreenect: 100-250 ms). Plain data with defaults.
struct AudioMotorOptions {
  UsbTimeout command_timeout{100};  ///< the bulk OUT command; never 0
  UsbTimeout reply_timeout{250};    ///< each bulk IN (state block, status); never 0
  bool reset_at_open = false;       ///< port-reset the audio device at open (13, row 9)
};

/// @brief Counters of the audio motor's exchanges.
struct AudioMotorStats {
  std::uint64_t commands = 0;     ///< commands answered with status OK
  std::uint64_t failures = 0;     ///< commands that failed (transfer, reply or status)
  std::uint64_t timeouts = 0;     ///< of which a transfer timed out
  std::uint64_t bad_replies = 0;  ///< malformed status or state block
};

/// @brief Tilt, LED and accelerometer of a 1473 / K4W through its running audio firmware.
/// @note Belongs to the transport's thread. Not copyable or movable. Never allocates after open().
class AudioMotor {
 public:
  /// @brief Finds the audio sibling of @p camera, checks its firmware runs, opens it (optionally
  /// resets it) and claims interface 0.
  /// @return USB / NOT_SUPPORTED for a 1414 camera, and for an audio device still in bootloader
  /// state (the message says: upload the firmware first); USB / NOT_FOUND when no audio sibling
  /// matches; USB / INVALID_PARAM for a zero timeout; USB errors of open and claim.
  [[nodiscard]] static Result<std::unique_ptr<AudioMotor>, KinectError> open(
      UsbTransport& transport, const CameraInfo& camera, AudioMotorOptions options = {});
  AudioMotor(const AudioMotor&) = delete;
  AudioMotor& operator=(const AudioMotor&) = delete;
  ~AudioMotor() = default;

  /// @brief Sends cmd 0x803B with arg2 = encode_audio_tilt(@p degrees).
  /// @return INVALID_ARGUMENT (nothing sent) if not finite or beyond +-31 degrees.
  [[nodiscard]] Result<void, KinectError> set_tilt(double degrees);
  /// @brief Sends cmd 0x10 with arg2 = audio_led_code(@p mode). @pre none.
  [[nodiscard]] Result<void, KinectError> set_led(LedMode mode);
  /// @brief Sends cmd 0x8032 (16 bytes), reads the 104-byte block, then the status.
  /// @return BAD_REPLY / BAD_LENGTH if the block is not 104 bytes; status failures as below.
  [[nodiscard]] Result<AudioMotorState, KinectError> read_state();

  /// @brief The audio function opened. @pre none.
  [[nodiscard]] const UsbDeviceInfo& info() const noexcept { return info_; }
  /// @brief The tag the next command carries (0 at open, +1 per command sent). @pre none.
  [[nodiscard]] std::uint32_t tag() const noexcept { return tag_; }
  /// @brief The counters so far. @pre none.
  [[nodiscard]] const AudioMotorStats& stats() const noexcept { return stats_; }

 private:
  AudioMotor(UsbTransport& transport, UsbDeviceHandle handle, const UsbDeviceInfo& info,
             AudioMotorOptions options) noexcept;
  // Sends @p command, reads @p block (if not empty) then the status. Status failures map to
  // BAD_REPLY (WRONG_LENGTH -> BAD_LENGTH, BAD_MAGIC, WRONG_TAG) or DEVICE_STATUS.
  [[nodiscard]] Result<std::size_t, KinectError> exchange(const AudioMotorCommand& command,
                                                          std::size_t command_bytes,
                                                          std::span<std::byte> block);

  UsbTransport* transport_;
  UsbDeviceHandle handle_;
  UsbDeviceInfo info_;
  AudioMotorOptions options_;
  std::uint32_t tag_ = 0;
  AudioMotorStats stats_{};
};

}  // namespace orthoflow::drivers::kinect
