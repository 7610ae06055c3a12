#pragma once
/// @file
/// @brief KinectCamera: one Kinect v1 camera on the USB seam (specs/KINECT_V1.md 10): discovery
/// and model detection, open (kernel driver detach, claim, K4W alternate setting), calibration,
/// the depth stream (isochronous transfers submitted first, then the start script), the frame
/// assembler, 11-bit unpacking, hole masking, a latest-frame mailbox for the consumer thread, the
/// stall watchdog and the reopen after an unplug.
///
/// Threads: everything but latest_depth() and health() runs on the USB thread, which calls pump()
/// in a loop (KinectDevice in kinect_device.hpp does). The frame path (iso callback, assembly,
/// unpack, publish) never allocates and never blocks: buffers are sized at open and start.
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "core/spin_lock.hpp"
#include "drivers/kinect/kinect_assembler.hpp"
#include "drivers/kinect/kinect_control.hpp"
#include "drivers/kinect/kinect_protocol.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

inline constexpr std::uint32_t DEPTH_WIDTH = 640;
inline constexpr std::uint32_t DEPTH_HEIGHT = 480;
inline constexpr std::size_t DEPTH_PIXELS = std::size_t{DEPTH_WIDTH} * DEPTH_HEIGHT;
inline constexpr double DEVICE_TICKS_PER_SECOND = 60e6;  ///< the 60 MHz frame timestamps

/// @brief A camera found on the bus.
struct CameraInfo {
  UsbDeviceInfo usb{};
  Model model = Model::K1414;
  core::FixedText<USB_SERIAL_MAX_BYTES> serial{};  ///< the camera's, or the audio sibling's
  bool has_motor = false;                          ///< a 0x02B0 sibling on the same hub (1414)
};
/// @brief Every Kinect v1 camera present, with serials resolved as libfreenect does (1473/K4W
/// cameras report "0000000000000000": the audio sibling's serial is used). @note Allocates.
[[nodiscard]] Result<std::vector<CameraInfo>, KinectError> list_cameras(UsbTransport& transport);

/// @brief How the camera is run.
struct CameraOptions {
  std::string_view serial{};  ///< which camera; empty = the first
  ControlPolicy control{};
  DepthFormat depth_format = DepthFormat::BITS_11;
  std::size_t iso_transfers = 16;  ///< KINECT_V1.md 2.1 (Linux)
  std::size_t iso_packets_per_transfer = 16;
  std::int64_t watchdog_ns = 500'000'000;  ///< no whole frame for this long: restart the stream
  std::int64_t reopen_interval_ns = 1'000'000'000;  ///< after an unplug: look for it this often
  /// Frames missing more packets than this are dropped (counted); fewer are delivered degraded,
  /// with the pixels of the missing packets set to "no reading". Default 10 % of 242.
  std::size_t max_missing_packets = 24;
  /// Also stream Bayer colour 640x480 at 30 Hz (EP 0x81) and pair each depth frame with the colour
  /// frame whose device timestamp is within pair_tolerance_ticks (default half a frame: 16.7 ms).
  bool colour = false;
  std::int64_t pair_tolerance_ticks = 1'000'000;
  /// Colour frames missing more packets than this are not paired (default 10 % of 162).
  std::size_t max_missing_colour_packets = 16;
};

/// @brief One depth frame as delivered: 640 x 480 raw disparities, 2047 = no reading (also where a
/// packet was missing).
struct DepthFrame {
  std::vector<std::uint16_t> raw;  ///< DEPTH_PIXELS, sized at start
  std::uint64_t device_ticks = 0;  ///< unwrapped 60 MHz device time
  std::int64_t host_ns = 0;        ///< transport clock when the last packet arrived
  std::uint64_t number = 0;        ///< frames the assembler delivered before it
  std::uint32_t missing_packets = 0;
  bool complete = false;  ///< no packet missing
  /// The paired colour frame (CameraOptions::colour): the raw GRBG Bayer mosaic, 640 x 480 bytes
  /// (kernels::demosaic_grbg turns it into RGB), sized at start; valid when has_colour.
  std::vector<std::uint8_t> bayer;
  bool has_colour = false;
  std::uint64_t colour_ticks = 0;  ///< the colour frame's device time
  bool colour_complete = false;    ///< the colour frame had every packet
};

/// @brief The camera's health, a snapshot (STYLE rule 16).
struct CameraHealth {
  AssemblerStats depth{};
  ControlStats control{};
  std::uint64_t frames_delivered = 0;    ///< published to the mailbox (whole or degraded)
  std::uint64_t frames_degraded = 0;     ///< published with holes
  std::uint64_t frames_dropped = 0;      ///< too many holes: not published
  std::uint64_t frames_overwritten = 0;  ///< published but replaced before the consumer took it
  std::uint64_t watchdog_restarts = 0;
  std::uint64_t unplugs = 0;
  std::uint64_t reopens = 0;
  std::uint64_t iso_errors = 0;       ///< packets with a status other than COMPLETED
  AssemblerStats colour{};            ///< the colour stream (CameraOptions::colour)
  std::uint64_t frames_paired = 0;    ///< depth frames published with their colour frame
  std::uint64_t depth_unpaired = 0;   ///< depth frames published without one (colour on)
  std::uint64_t colour_unpaired = 0;  ///< colour frames no depth frame took
  std::uint64_t colour_dropped = 0;   ///< colour frames with too many missing packets
  std::int64_t last_frame_host_ns = 0;
  bool streaming = false;
  bool device_lost = false;
};

/// @brief The frame path's decode step: unpacks an assembled depth frame of @p format into @p raw
/// and sets every pixel a missing packet touched to RAW_NO_READING (2047). @p scalar selects the
/// scalar twin of the unpack kernel (benchmarks and tests). @pre raw.size() == DEPTH_PIXELS.
/// @note Never allocates.
void decode_depth(const AssembledFrame& frame, const StreamGeometry& geometry, DepthFormat format,
                  std::span<std::uint16_t> raw, bool scalar = false) noexcept;

/// @brief One named counter of CameraHealth (name: static storage).
struct HealthCounter {
  const char* name = "";
  std::uint64_t value = 0;
};
inline constexpr std::size_t HEALTH_COUNTERS = 20;
/// @brief The counters of @p health that people read (CLI, telemetry), named once, here.
/// @note Never allocates.
[[nodiscard]] std::array<HealthCounter, HEALTH_COUNTERS> health_counters(
    const CameraHealth& health) noexcept;

/// @brief One open camera. Create with open(); not copyable or movable (callbacks point at it).
class KinectCamera {
 public:
  /// @brief Finds the camera @p options names, opens it and reads its calibration.
  [[nodiscard]] static Result<std::unique_ptr<KinectCamera>, KinectError> open(
      UsbTransport& transport, const CameraOptions& options = {});
  ~KinectCamera();
  KinectCamera(const KinectCamera&) = delete;
  KinectCamera& operator=(const KinectCamera&) = delete;

  /// @brief Starts depth (and colour, with CameraOptions::colour): submits the isochronous
  /// transfers, then writes the start scripts.
  [[nodiscard]] Result<void, KinectError> start_depth();
  /// @brief Writes the stop register, then cancels the transfers and drains them.
  [[nodiscard]] Result<void, KinectError> stop_depth();
  /// @brief Runs the transport's events for up to @p timeout, then the watchdog: restarts a stalled
  /// stream, notices an unplug and reopens the device when it is back. Errors are counted in
  /// health() and returned; the camera stays usable (the next pump tries again).
  [[nodiscard]] Result<void, KinectError> pump(UsbTimeout timeout);

  /// @brief Consumer side (any one thread): the newest frame published since the last call, or
  /// nullptr. The frame stays valid until the next call. @note Wait-free; never allocates.
  [[nodiscard]] const DepthFrame* latest_depth() noexcept;
  /// @brief A snapshot of the counters. @note Any thread; a short spin lock.
  [[nodiscard]] CameraHealth health() const noexcept;

  /// @brief What was opened. @pre none.
  [[nodiscard]] const CameraInfo& info() const noexcept { return info_; }
  /// @brief The calibration read at open. @pre none.
  [[nodiscard]] const Calibration& calibration() const noexcept { return calibration_; }
  /// @brief The command channel (tilt-free register access for tools). @pre USB thread only.
  [[nodiscard]] KinectControl& control() noexcept { return *control_; }

 private:
  KinectCamera(UsbTransport& transport, const CameraOptions& options);
  [[nodiscard]] Result<void, KinectError> attach(const CameraInfo& info);
  void on_packet(std::span<const std::byte> bytes, UsbPacketStatus status,
                 FrameAssembler& assembler) noexcept;
  void stop_transfers() noexcept;
  void on_frame(const AssembledFrame& frame) noexcept;
  void on_colour(const AssembledFrame& frame) noexcept;
  void publish_depth() noexcept;
  [[nodiscard]] bool pair_with_ring(DepthFrame& slot) noexcept;
  void attach_colour(DepthFrame& slot, std::size_t ring_index) noexcept;
  void reset_pairing() noexcept;
  void publish_health() noexcept;
  [[nodiscard]] Result<void, KinectError> restart_depth();
  [[nodiscard]] Result<void, KinectError> try_reopen();

  UsbTransport* transport_;
  CameraOptions options_;
  std::string serial_;  // options_.serial points into the caller's memory: keep our own copy
  CameraInfo info_{};
  UsbDeviceHandle handle_{};
  std::unique_ptr<KinectControl> control_;
  Calibration calibration_{};
  std::size_t packet_size_ = ISO_PACKET_FALLBACK;
  std::unique_ptr<FrameAssembler> assembler_;
  std::unique_ptr<FrameAssembler> colour_assembler_;
  // The last colour frames, waiting for their depth frame; a depth frame that finds no partner yet
  // waits in back_ (pending_) until the next colour frame tells whether one is coming.
  struct ColourSlot {
    std::vector<std::uint8_t> bayer;
    std::uint64_t ticks = 0;
    bool valid = false;
    bool used = false;
    bool complete = false;
  };
  std::array<ColourSlot, 2> colour_ring_{};
  std::size_t colour_next_ = 0;
  bool pending_ = false;
  bool want_streaming_ = false;
  bool streaming_ = false;
  bool lost_ = false;
  std::int64_t stream_started_ns_ = 0;
  std::int64_t next_reopen_ns_ = 0;

  // Triple buffer: the USB thread fills back_, then swaps it with middle_; the consumer swaps
  // front_ with middle_ when middle_ is fresh. state_ = middle index | FRESH bit.
  static constexpr std::uint8_t FRESH = 0x4;
  std::array<DepthFrame, 3> slots_{};
  std::uint8_t back_ = 0;
  std::uint8_t front_ = 2;
  std::atomic<std::uint8_t> state_{1};

  CameraHealth local_{};  // USB thread's counters
  mutable core::SpinLock health_lock_;
  CameraHealth shared_{};  // snapshot for other threads
};

}  // namespace orthoflow::drivers::kinect
