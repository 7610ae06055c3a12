#pragma once
/// @file
/// @brief The model-1414 motor, LED and accelerometer function (PID 0x02B0, specs/KINECT_V1.md 11):
/// first the protocol as pure functions over bytes (tilt encoding, LED codes, the 10-byte state
/// reply), then KinectMotor, the device over the USB seam. Control transfers only, on EP0, each
/// with a finite timeout.
///
/// Models 1473 and K4W have no 0x02B0 function: their motor and LED are driven through the audio
/// device once its firmware is uploaded (KINECT_V1.md 12). KinectMotor::open() then uses the
/// AudioMotor backend of kinect_audio.hpp when the audio firmware runs, and refuses with a
/// NOT_SUPPORTED error telling the user to upload the firmware first while it does not.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "core/result.hpp"
#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_control.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

// ---- The protocol, pure (KINECT_V1.md 11) -------------------------------------------------------

inline constexpr double MOTOR_TILT_LIMIT_DEG = 31.0;  ///< libfreenect's limit; past it the motor
                                                      ///< may stall
inline constexpr double ACCEL_COUNTS_PER_G = 819.0;   ///< Kionix KXSD9
inline constexpr double STANDARD_GRAVITY_MPS2 = 9.80665;
inline constexpr std::size_t MOTOR_STATE_BYTES = 10;  ///< the 0xC0/0x32 reply
/// @brief Tilt byte meaning "no reading". Not in the brief (KINECT_V1.md 11 gives no such value):
/// -128 is our choice, since a real angle of -64 degrees is far outside the motor's range.
inline constexpr std::int8_t TILT_RAW_NO_READING = -128;

inline constexpr UsbControlSetup MOTOR_SET_TILT{0x40, 0x31, 0, 0};    ///< wValue = encode_tilt()
inline constexpr UsbControlSetup MOTOR_SET_LED{0x40, 0x06, 0, 0};     ///< wValue = LedMode
inline constexpr UsbControlSetup MOTOR_READ_STATE{0xC0, 0x32, 0, 0};  ///< wLength 10

/// @brief wValue of a set-tilt request: signed 16-bit 2 x @p degrees (two's complement), clamped
/// to +-31 degrees (+-62) and rounded to the nearest half degree (halves away from zero), as
/// libfreenect sends it. Not-a-number encodes 0 (level).
/// @pre none. @note Pure; KinectMotor::set_tilt refuses what this would clamp (STYLE rule 17).
[[nodiscard]] std::uint16_t encode_tilt(double degrees) noexcept;

/// @brief LED codes of the 1414 (wValue of 0x40/0x06). Only OFF..YELLOW (0-3) are certain: for 4-7
/// libfreenect and the 2010 notes disagree (KINECT_V1.md 13, row 3); these follow libfreenect,
/// where 5 repeats 4 and is left out.
enum class LedMode : std::uint8_t {
  OFF = 0,
  GREEN = 1,
  RED = 2,
  YELLOW = 3,
  BLINK_GREEN = 4,       ///< uncertain (2010 notes: blink yellow)
  BLINK_RED_YELLOW = 6,  ///< uncertain (2010 notes agree on "alternate red-yellow")
};
/// @brief "off", "green", "red", "yellow", "blink-green", "blink-red-yellow". @pre none.
[[nodiscard]] const char* to_string(LedMode mode) noexcept;
/// @brief The mode named @p name (the to_string() spelling), or nullopt. @pre none. @note Pure.
[[nodiscard]] std::optional<LedMode> parse_led_mode(std::string_view name) noexcept;

/// @brief Byte 9 of the state. Values other than 0, 1, 4 (a book lists 0x08 = stall) are UNKNOWN,
/// to be treated as an error (KINECT_V1.md 13, row 13); MotorState keeps the raw byte.
enum class TiltStatus : std::uint8_t { STOPPED = 0x00, AT_LIMIT = 0x01, MOVING = 0x04, UNKNOWN };
/// @brief "stopped", "at_limit", "moving" or "unknown". @pre none.
[[nodiscard]] const char* to_string(TiltStatus status) noexcept;

/// @brief The decoded 10-byte state reply.
struct MotorState {
  std::array<std::int16_t, 3> accel_counts{};  ///< x, y, z: big-endian int16 at bytes 2..7
  std::array<double, 3> accel_g{};             ///< counts / 819
  std::array<double, 3> accel_mps2{};          ///< accel_g x 9.80665
  std::int8_t tilt_raw = 0;                    ///< byte 8: half degrees
  std::optional<double> tilt_deg{};            ///< tilt_raw / 2; nullopt for -128 (no reading)
  TiltStatus status = TiltStatus::UNKNOWN;
  std::uint8_t status_raw = 0;  ///< byte 9 as sent
};

/// @brief Decodes a state reply. Bytes 0-1 are ignored (unverified meaning). @return nullopt unless
/// @p reply is exactly MOTOR_STATE_BYTES long. @pre none. @note Pure, never allocates; @p reply is
/// untrusted device data and every byte value is accepted.
[[nodiscard]] std::optional<MotorState> decode_motor_state(
    std::span<const std::byte> reply) noexcept;

// ---- The device ---------------------------------------------------------------------------------

/// @brief How patient the motor is. Plain data with defaults.
struct MotorOptions {
  UsbTimeout transfer_timeout{500};  ///< per control transfer; never 0 (infinite)
  UsbTimeout poll_interval{50};      ///< wait_until_still: one state read this often
  /// 1473/K4W only: port-reset the audio device at open (KINECT_V1.md 13, row 9: libfreenect does
  /// it to avoid hangs, issue #543 says it hurts). Off by default. The audio backend uses its own
  /// 100 / 250 ms bulk timeouts (AudioMotorOptions), not transfer_timeout.
  bool reset_audio_at_open = false;
};

/// @brief Counters of the motor's control transfers (STYLE rule 16).
struct MotorStats {
  std::uint64_t requests = 0;     ///< control transfers that succeeded
  std::uint64_t failures = 0;     ///< control transfers that failed (timeouts included)
  std::uint64_t timeouts = 0;     ///< of which timed out
  std::uint64_t bad_replies = 0;  ///< state replies that were not 10 bytes
  std::uint64_t polls = 0;        ///< state reads made by wait_until_still
};

class AudioMotor;  // kinect_audio.hpp: the 1473/K4W backend

/// @brief The open motor/LED/accelerometer function of one Kinect: the 0x02B0 function of a 1414,
/// or the running audio firmware of a 1473 / K4W (AudioMotor backend).
/// @note Belongs to the transport's thread, like the transport. Not copyable or movable. Never
/// allocates after open().
class KinectMotor {
 public:
  /// @brief Finds the PID 0x02B0 sibling of @p camera (same parent hub; else the only one on the
  /// same bus; else the only one), opens it and claims interface 0. For a 1473 or K4W camera, opens
  /// the audio sibling through AudioMotor::open instead.
  /// @return USB / NOT_SUPPORTED for a 1473 or K4W camera whose audio firmware is not running (the
  /// message says to upload it first); USB / NOT_FOUND when no motor matches; USB errors of open
  /// and claim.
  /// @pre @p transport outlives the motor.
  [[nodiscard]] static Result<std::unique_ptr<KinectMotor>, KinectError> open(
      UsbTransport& transport, const CameraInfo& camera, MotorOptions options = {});
  KinectMotor(const KinectMotor&) = delete;
  KinectMotor& operator=(const KinectMotor&) = delete;
  ~KinectMotor();

  /// @brief Asks the firmware to servo to @p degrees from the horizon (not from the base). The
  /// device resolves half degrees: the value sent is encode_tilt(degrees).
  /// @return INVALID_ARGUMENT (nothing sent) if @p degrees is not finite or beyond
  /// +-MOTOR_TILT_LIMIT_DEG: limits are refused, never clipped (STYLE rule 17).
  [[nodiscard]] Result<void, KinectError> set_tilt(double degrees);
  /// @brief Sets the LED. @pre none.
  [[nodiscard]] Result<void, KinectError> set_led(LedMode mode);
  /// @brief Reads and decodes the 10-byte state. @return BAD_REPLY / TOO_SHORT if fewer bytes came.
  /// 1473/K4W: the 104-byte block converted by to_motor_state() (status UNKNOWN: the block has no
  /// motion status).
  [[nodiscard]] Result<MotorState, KinectError> read_state();
  /// @brief Reads the state every poll_interval on the transport's clock, pumping the transport's
  /// events in between (handle_events, never a busy loop), until the status is not MOVING.
  /// @return that state (STOPPED, AT_LIMIT or UNKNOWN: the caller judges); USB / TIMEOUT if it
  /// was still moving after @p timeout; the first failed read's error.
  /// 1473/K4W (no status in the block): "still" is inferred as reading the whole-degree angle last
  /// sent by set_tilt; that state is returned with status STOPPED (status_raw 0). A head held back
  /// from its target therefore times out. Before any set_tilt the first reading is returned.
  [[nodiscard]] Result<MotorState, KinectError> wait_until_still(UsbTimeout timeout);

  /// @brief The motor function opened (the audio function on a 1473 / K4W). @pre none.
  [[nodiscard]] const UsbDeviceInfo& info() const noexcept { return info_; }
  /// @brief The counters so far. @pre none.
  [[nodiscard]] const MotorStats& stats() const noexcept { return stats_; }

 private:
  KinectMotor(UsbTransport& transport, UsbDeviceHandle handle, const UsbDeviceInfo& info,
              MotorOptions options) noexcept;
  KinectMotor(UsbTransport& transport, std::unique_ptr<AudioMotor> audio,
              MotorOptions options) noexcept;
  void count(const KinectError* failure) noexcept;
  [[nodiscard]] Result<std::size_t, KinectError> transfer(const UsbControlSetup& setup,
                                                          std::span<std::byte> data);

  UsbTransport* transport_;
  UsbDeviceHandle handle_;
  UsbDeviceInfo info_;
  MotorOptions options_;
  MotorStats stats_{};
  std::unique_ptr<AudioMotor> audio_;           // set for 1473 / K4W
  std::optional<std::int32_t> audio_target_{};  // the last tilt sent to the audio backend
};

}  // namespace orthoflow::drivers::kinect
