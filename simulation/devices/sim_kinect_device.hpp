#pragma once
/// @file
/// @brief SimKinectDevice: one simulated Kinect v1 (camera, 1414 motor, audio bootloader and
/// firmware) implementing the documented protocol of specs/KINECT_V1.md (sections 1, 2, 4, 5, 6,
/// 7, 11, 12) on simulated time, for testing the driver on a machine without USB. It is
/// transport-independent: a host (SimUsbHost through SimKinectUsbDevice, or the libusb-compatible
/// shim of tests/support/sim_libusb) routes control requests, bulk transfers and iso microframes to
/// it and owns bus addresses, claims and kernel-driver state. Its configuration:
/// sim_kinect_config.hpp. It has never been compared with a real Kinect: it is exactly as right as
/// the brief it implements.
///
/// Camera (EP0): "GM" commands as OUT 0x40/0/0/0, "RB" replies read with IN 0xC0/0/0/0 (0 bytes
/// while no reply is pending). Opcodes 0x02 GET_PARAM, 0x03 SET_PARAM, 0x04 GET_FIXED_PARAMS,
/// 0x16 ALGORITHM_PARAMS (0x00, 0x40, 0x41), 0x95 CMOS register access; anything else is answered
/// with status 1. A malformed command (setup not 0x40/0/0/0, no "GM", length mismatch, odd or
/// longer than 1016 bytes of payload) is refused (PIPE) and leaves no reply.
/// Streams: reg 0x06 <- 2 starts depth on 0x82 (format reg 0x12: 3 = 11-bit, 2 = 10-bit, anything
/// else starts nothing), reg 0x05 <- 1 Bayer, <- 3 IR 640x488 on 0x81; 0 stops. The first frame
/// starts in the microframe after the write. Mirror registers (0x17, 0x47, 0x48) are stored only.
/// Motor (1414 only): tilt 0x40/0x31, LED 0x40/0x06, state 0xC0/0x32 (10 bytes), probe 0xC0/0x10.
/// Audio (0x02AD; 0x02BE on K4W; KINECT_V1.md 12), bulk 0x01 OUT / 0x81 IN, no control requests:
/// - bootloader state (1 interface): 24-byte commands (magic 0x06022009; a malformed one is refused
///   with PIPE). Write (cmd 3): bytes 1..0x4000, then bulk OUT data writes of 1..512 bytes (longer
///   ones, or more than announced: PIPE), then the 12-byte status (magic 0x0A6FE000, tag echo).
///   A nonzero status answers a tag that is not the previous + 1 (the first may be anything), a
///   bad length, an address that does not continue from base_addr, a first chunk whose header
///   (0xCA77F00D, base_addr = the write's address) is wrong, and the fault chunk. Accepted chunks
///   are kept (audio_image()). Execute (cmd 4, bytes 0, addr = entry_addr, after exactly `size`
///   bytes): status 0, then the function disconnects when that status is read and reappears after
///   audio_reenumerate_delay_ns with the same serial, a new address and 2 interfaces.
/// - running state: 20-byte commands LED (cmd 0x10, arg2 1..4), tilt (0x803B, signed degrees,
///   clamped to +-31 by the simulated firmware, slewing like the 1414 motor), state (0x8032, arg1
///   0x68, 16 bytes are enough): the 104-byte block (int32 x, y, z at 16, 20, 24 from the same
///   gravity model as the 1414, 819 counts/g; int32 degrees at 28), then the status. An unknown
///   command or argument gets status 1.
/// - an IN with nothing to send times out; unplug / replug returns it to the bootloader.
/// Thread safety: none; one host thread drives it. Determinism: given the call sequence and times,
/// every byte is a function of the config (its seed and sources).
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "core/rng.hpp"
#include "drivers/usb/usb_transport.hpp"
#include "simulation/devices/sim_kinect_config.hpp"
#include "simulation/devices/sim_kinect_stream.hpp"
#include "simulation/devices/sim_usb_device.hpp"

namespace orthoflow::simulation {

/// @brief One simulated Kinect: identity, EP0 protocols, iso microframes, motor.
/// @note Not copyable or movable (its streams call back into it). Allocates in the constructor
/// and once for the default scene; nothing per packet or per frame.
class SimKinectDevice {
 public:
  /// @pre serial is 16 chars for model 1414; hub_ports has 1..6 entries; slew > 0 (OF_ENFORCE).
  explicit SimKinectDevice(SimKinectConfig config);
  SimKinectDevice(const SimKinectDevice&) = delete;
  SimKinectDevice& operator=(const SimKinectDevice&) = delete;

  [[nodiscard]] const SimKinectConfig& config() const noexcept { return config_; }
  [[nodiscard]] KinectModel model() const noexcept { return config_.model; }
  /// @brief True if this model has @p function (MOTOR: 1414 only; AUDIO: if with_audio).
  [[nodiscard]] bool has_function(KinectFunction function) const noexcept;
  /// @brief The enumeration record of @p function at the addresses the host assigned (camera at
  /// first_address, motor + 1, audio + 2). @pre has_function(function).
  [[nodiscard]] drivers::UsbDeviceInfo info(KinectFunction function) const noexcept;
  /// @brief The host assigns addresses on (re)connection. @pre address <= 125.
  void set_first_address(std::uint8_t address) noexcept { first_address_ = address; }
  /// @brief Power-on state: registers, pending reply, streams; the motor keeps its angle.
  void power_cycle() noexcept;

  /// @brief A control transfer to @p function at simulated time @p now_ns. @p data is the OUT
  /// payload or the IN buffer (wLength = data.size()).
  SimControlReply control(KinectFunction function, const drivers::UsbControlSetup& setup,
                          std::span<std::byte> data, std::int64_t now_ns) noexcept;
  /// @brief A bulk transfer to @p function's @p endpoint at @p now_ns (audio only: 0x01, 0x81).
  /// @p data is the OUT payload or the IN buffer. TIMEOUT: nothing to send, or a stall fault.
  SimControlReply bulk(KinectFunction function, std::uint8_t endpoint, std::span<std::byte> data,
                       std::int64_t now_ns) noexcept;
  /// @brief False while the audio function is away re-enumerating (and forever without
  /// re-enumeration). Every other function is present when the Kinect is.
  [[nodiscard]] bool present(KinectFunction function, std::int64_t now_ns) const noexcept;
  /// @brief Bumped when the audio function disconnects to re-enumerate: handles opened before are
  /// dead, and the host assigns a new address (set_audio_address) once it is back.
  [[nodiscard]] std::uint32_t audio_generation() const noexcept { return audio_.generation; }
  void set_audio_address(std::uint8_t address) noexcept { audio_.address = address; }
  [[nodiscard]] SimAudioState audio_state(std::int64_t now_ns) const noexcept;
  /// @brief Bootloader and firmware back at power-on (unplug / replug).
  void audio_power_on() noexcept;
  /// @brief The image bytes accepted so far, from base_addr on.
  [[nodiscard]] const std::vector<std::uint8_t>& audio_image() const noexcept {
    return audio_.image;
  }
  /// @brief Every audio command received, in order (bootloader, then firmware).
  [[nodiscard]] const std::vector<SimAudioCommand>& audio_commands() const noexcept {
    return audio_.commands;
  }
  /// @brief The length of every bootloader data write (bulk OUT after a write command), in order.
  [[nodiscard]] const std::vector<std::size_t>& audio_data_writes() const noexcept {
    return audio_.data_writes;
  }
  /// @brief The LED code last set on the running audio firmware (1 off .. 4 red; 0 never set).
  [[nodiscard]] std::uint32_t audio_led() const noexcept { return audio_.led; }

  /// @brief The camera's packet in microframe @p microframe on @p endpoint (0x81 / 0x82) into @p
  /// out; returns its length (0 = idle). Call per endpoint with increasing microframes.
  /// @pre out.size() >= KINECT_ISO_MAX_PACKET_BYTES.
  std::size_t iso_packet(std::uint8_t endpoint, std::int64_t microframe,
                         std::span<std::byte> out) noexcept;

  /// @brief The raw disparity image the depth stream sends as frame @p frame (frames count from 0
  /// at every stream start). In 10-bit mode each pixel is sent as min(raw, 1023).
  /// @pre raw.size() == 640 * 480.
  void depth_raw_image(std::uint64_t frame, std::span<std::uint16_t> raw);
  /// @brief The Bayer frame @p frame. @pre bayer.size() == 640 * 480.
  void bayer_image(std::uint64_t frame, std::span<std::uint8_t> bayer);
  /// @brief The IR frame @p frame. @pre ir.size() == 640 * 488.
  void ir_image(std::uint64_t frame, std::span<std::uint16_t> ir);

  /// @brief A camera register's value (nullopt if never written).
  [[nodiscard]] std::optional<std::uint16_t> reg(std::uint16_t address) const;
  /// @brief Every SET_PARAM (reg, value) in arrival order.
  [[nodiscard]] const std::vector<std::pair<std::uint16_t, std::uint16_t>>& register_writes()
      const noexcept {
    return writes_;
  }
  [[nodiscard]] SimStreamMode depth_mode() const noexcept { return depth_.mode(); }
  [[nodiscard]] SimStreamMode video_mode() const noexcept { return video_.mode(); }
  [[nodiscard]] const SimStreamCounters& depth_counters() const noexcept {
    return depth_.counters();
  }
  [[nodiscard]] const SimStreamCounters& video_counters() const noexcept {
    return video_.counters();
  }
  /// @brief GM commands accepted (malformed ones excluded).
  [[nodiscard]] std::uint64_t commands() const noexcept { return commands_; }

  /// @brief Motor angle at @p now_ns (degrees, slewing toward target_tilt_deg()).
  [[nodiscard]] double tilt_deg(std::int64_t now_ns) noexcept;
  [[nodiscard]] double target_tilt_deg() const noexcept { return motor_.target_deg; }
  /// @brief The head's pitch at motor angle 0 (SimKinectConfig::mount_pitch_deg, resolved).
  [[nodiscard]] double mount_pitch_deg() noexcept;
  [[nodiscard]] std::uint8_t led() const noexcept { return motor_.led; }

  [[nodiscard]] const SimKinectFaults& faults() const noexcept { return faults_; }
  /// @brief Replaces the fault knobs (e.g. to arm a one-shot mid-test).
  void set_faults(const SimKinectFaults& faults) noexcept { faults_ = faults; }

 private:
  struct Motor {
    double angle_deg = 0.0;
    double target_deg = 0.0;
    bool clamped = false;
    std::int64_t updated_ns = 0;
    std::uint8_t led = 0;
  };

  struct Audio {
    enum class Phase : std::uint8_t { IDLE, DATA, STATUS, BLOCK };
    Phase phase = Phase::IDLE;
    bool running = false;
    bool tag_seen = false;
    std::uint32_t last_tag = 0;
    std::uint32_t tag = 0;  // of the command being answered
    std::uint32_t status = 0;
    std::uint32_t cmd = 0;
    std::uint32_t chunk_addr = 0;
    std::size_t data_left = 0;
    std::size_t chunks = 0;  // write commands received
    bool have_header = false;
    std::uint32_t base_addr = 0;
    std::uint32_t size = 0;
    std::uint32_t entry_addr = 0;
    bool execute_pending = false;
    std::optional<std::int64_t> gone_ns{};
    std::optional<std::int64_t> back_ns{};  // nullopt while gone: never
    std::uint32_t generation = 0;
    std::optional<std::uint8_t> address{};
    std::uint32_t led = 0;
    std::array<std::byte, 104> block{};
    std::vector<std::uint8_t> chunk;
    std::vector<std::uint8_t> image;
    std::vector<SimAudioCommand> commands;
    std::vector<std::size_t> data_writes;
  };

  SimControlReply audio_out(std::span<const std::byte> data, std::int64_t now_ns) noexcept;
  SimControlReply audio_in(std::span<std::byte> data, std::int64_t now_ns) noexcept;
  void bootloader_command(std::span<const std::byte> data) noexcept;
  void bootloader_chunk_done() noexcept;
  void firmware_command(std::span<const std::byte> data, std::int64_t now_ns) noexcept;
  SimControlReply camera_control(const drivers::UsbControlSetup& setup, std::span<std::byte> data,
                                 std::int64_t now_ns) noexcept;
  SimControlReply read_reply(std::span<std::byte> data) noexcept;
  bool gm_command(std::span<const std::byte> data, std::int64_t now_ns) noexcept;
  void answer(std::uint16_t cmd, std::uint16_t tag, std::span<const std::uint8_t> payload,
              std::int64_t now_ns) noexcept;
  std::size_t algorithm_params(std::uint16_t param_id, std::span<std::uint8_t> out) const noexcept;
  std::size_t fixed_params(std::span<std::uint8_t> out) const noexcept;
  void write_register(std::uint16_t address, std::uint16_t value, std::int64_t now_ns) noexcept;
  SimControlReply motor_control(const drivers::UsbControlSetup& setup, std::span<std::byte> data,
                                std::int64_t now_ns) noexcept;
  void fill_frame(SimStreamMode mode, std::uint64_t frame, std::span<std::uint8_t> packed);
  void ensure_default_scene();

  SimKinectConfig config_;
  SimKinectFaults faults_;
  core::Rng rng_;
  std::uint8_t first_address_ = 0;
  std::map<std::uint16_t, std::uint16_t> registers_;
  std::map<std::uint16_t, std::uint16_t> cmos_registers_;
  std::vector<std::pair<std::uint16_t, std::uint16_t>> writes_;
  std::array<std::uint8_t, 512> reply_{};
  std::size_t reply_bytes_ = 0;
  bool reply_pending_ = false;
  std::uint32_t junk_left_ = 0;
  std::uint32_t empty_left_ = 0;
  std::uint64_t commands_ = 0;
  SimIsoStreamGenerator depth_;
  SimIsoStreamGenerator video_;
  std::vector<std::uint16_t> scratch16_;  // 640 x 488: a frame before packing
  std::vector<std::uint8_t> scratch8_;
  std::vector<std::uint16_t> scene_raw_;  // the default scene, rendered on first use
  std::vector<std::uint8_t> scene_bayer_;
  std::vector<std::uint16_t> scene_ir_;
  Motor motor_{};
  std::optional<double> mount_pitch_{};  // resolved on first use
  Audio audio_{};
};

}  // namespace orthoflow::simulation
