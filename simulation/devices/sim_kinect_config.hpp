#pragma once
/// @file
/// @brief The configuration of a simulated Kinect v1 (sim_kinect_device.hpp): models, functions,
/// USB ids, frame sources, fault knobs, calibration answers, and the audio function's log records.
/// Plain data with defaults; SimKinectDevice validates it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "simulation/devices/sim_kinect_stream.hpp"
#include "simulation/world/kinect_depth_model.hpp"

namespace orthoflow::simulation {

/// @brief Kinect models (KINECT_V1.md 1): 1414 has a motor function, 1473 and K4W do not.
enum class KinectModel : std::uint8_t { K1414, K1473, K4W };
/// @brief The USB functions behind a Kinect's internal hub.
enum class KinectFunction : std::uint8_t { CAMERA, MOTOR, AUDIO };

inline constexpr std::uint16_t KINECT_VENDOR = 0x045E;
inline constexpr std::uint16_t KINECT_CAMERA_PID = 0x02AE;
inline constexpr std::uint16_t KINECT_K4W_CAMERA_PID = 0x02BF;
inline constexpr std::uint16_t KINECT_MOTOR_PID = 0x02B0;
inline constexpr std::uint16_t KINECT_AUDIO_PID = 0x02AD;
inline constexpr std::uint16_t KINECT_K4W_AUDIO_PID = 0x02BE;
inline constexpr std::uint8_t KINECT_VIDEO_ENDPOINT = 0x81;
inline constexpr std::uint8_t KINECT_DEPTH_ENDPOINT = 0x82;

/// @brief 640x480 raw disparity (11 bits, 2047 = no reading) of frame @p frame since stream start.
using SimDepthSource = std::function<void(std::uint64_t frame, std::span<std::uint16_t> raw)>;
/// @brief 640x480 8-bit GRBG Bayer mosaic of frame @p frame.
using SimBayerSource = std::function<void(std::uint64_t frame, std::span<std::uint8_t> bayer)>;
/// @brief 640x488 10-bit IR of frame @p frame.
using SimIrSource = std::function<void(std::uint64_t frame, std::span<std::uint16_t> ir)>;

/// @brief Fault knobs; all off by default. Rates are per packet; counts and one-shots are consumed
/// as they fire (faults() shows what is left). Times are simulated ns; the host applies them.
struct SimKinectFaults {
  SimPacketFaults packets{};         ///< drop / duplicate / corrupt / reorder rates, both streams
  std::uint32_t junk_replies = 0;    ///< per GM command: 512-byte junk IN replies first (USB 3)
  std::uint32_t empty_replies = 0;   ///< per GM command: then 0-byte IN replies
  std::uint32_t control_stalls = 0;  ///< the next N control transfers (any function) time out
  bool wrong_tag_once = false;       ///< the next GM reply carries tag + 1
  bool wrong_magic_once = false;     ///< the next GM reply starts "RC" instead of "RB"
  std::optional<std::int64_t> disconnect_at_ns{};  ///< unplug: NO_DEVICE, gone from enumerate
  std::optional<std::int64_t> reconnect_at_ns{};   ///< replug (after disconnect) at new addresses
  std::optional<std::int64_t> cancel_at_ns{};      ///< in-flight iso transfers come back CANCELLED
  std::optional<std::uint32_t> audio_bad_status_chunk{};  ///< this write (0-based) gets status 5
  std::uint32_t audio_bulk_stalls = 0;    ///< the next N audio bulk transfers time out (no effect)
  bool audio_no_reenumeration = false;    ///< after execute the audio function never comes back
  bool audio_back_as_bootloader = false;  ///< it comes back, still with 1 interface
  bool audio_wrong_tag_once = false;      ///< the next audio status carries tag + 1
};

/// @brief Device calibration answered by opcodes 0x04 and 0x16 (not real calibration data).
struct SimKinectCalibration {
  double dcmos_rcmos_dist_cm = 2.3;  ///< fixed params float 2 (the others: KinectDepthParams)
  std::uint16_t pad_start_lines = 0;
  std::uint16_t pad_end_lines = 0;
  std::uint16_t pad_cropping_lines = 0;
  std::array<std::int32_t, 29> registration{};  ///< 0x16/0x40 words; all 0 = built-in pattern
};

/// @brief One simulated Kinect. Plain data with defaults; validated by the constructor.
struct SimKinectConfig {
  KinectModel model = KinectModel::K1414;
  std::string serial = "A00364A11700045A";  ///< 16 chars; the 1414 camera's (1473/K4W: audio's)
  std::uint8_t bus = 1;
  std::vector<std::uint8_t> hub_ports{1};  ///< port path of the Kinect's internal hub
  bool with_audio = true;                  ///< list the audio function
  KinectDepthParams depth{};  ///< fixed params floats, const shift, default scene conversion
  SimKinectCalibration calibration{};
  SimDepthSource depth_source{};  ///< empty: a seeded synthetic tabletop, rendered once
  SimBayerSource bayer_source{};  ///< empty: that scene's colours as GRBG
  SimIrSource ir_source{};        ///< empty: an intensity falling with depth squared
  std::uint64_t scene_seed = 42;
  /// The head's pitch at motor angle 0 (degrees, negative: looking down), the Kinect standing on a
  /// pitched bracket: the accelerometer reads gravity for the motor angle plus this, so that "up"
  /// agrees with the scene the camera sees. nullopt: the default scene's own pitch (its table is
  /// level), or 0 with a depth_source.
  std::optional<double> mount_pitch_deg{};
  double motor_slew_deg_per_s = 15.0;
  std::int64_t audio_reenumerate_delay_ns = 1'500'000'000;  ///< execute -> reappearance
  bool audio_firmware_running = false;  ///< start (and replug) with the firmware already running
  std::uint64_t fault_seed = 1;         ///< seeds the core::Rng of every random fault
  SimKinectFaults faults{};
};

/// @brief The audio function's state (KINECT_V1.md 12.1).
enum class SimAudioState : std::uint8_t { BOOTLOADER, GONE, RUNNING };

/// @brief One audio command as the simulated device received it (bootloader or firmware).
struct SimAudioCommand {
  std::uint32_t tag = 0;
  std::uint32_t cmd = 0;
  std::uint32_t word2 = 0;   ///< bootloader: bytes; firmware: arg1
  std::uint32_t word4 = 0;   ///< bootloader: addr; firmware: arg2 (0 if not sent)
  std::uint32_t status = 0;  ///< the status answered
};

}  // namespace orthoflow::simulation
