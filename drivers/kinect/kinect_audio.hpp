#pragma once
/// @file
/// @brief Models 1473 and K4W: the audio function's firmware upload and the motor, LED and
/// accelerometer through the running audio firmware (specs/KINECT_V1.md 12). First the protocol as
/// pure functions over bytes (the 24-byte bootloader command, the 12-byte status, the firmware
/// image header, the 20-byte motor command, the 104-byte state block), in kinect_audio_protocol.hpp
/// and included here; then FirmwareLoader and AudioMotor over the USB seam. Bulk transfers on EP
/// 0x01 (OUT) and 0x81 (IN), each with a finite timeout.
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
#include "drivers/kinect/kinect_audio_protocol.hpp"
#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_control.hpp"
#include "drivers/kinect/kinect_motor.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

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
