#pragma once
/// @file
/// @brief The isochronous side of the simulated Kinect v1 (KINECT_V1.md 6, 7): an MSB-first bit
/// packer written for the simulator (independent of kernels/, so a driver's unpacker is checked
/// against a second implementation), and SimIsoStreamGenerator, which turns frames into the 12-byte
/// header + payload device packets of one iso endpoint, one per 125 us microframe, with seeded
/// bus faults (drop, duplicate, corrupt, swap adjacent).
///
/// Timing: frame k of a stream started at microframe s begins at microframe s + floor(k * 800 / 3)
/// (30 Hz on the 8000 microframes of a second) and takes one microframe per packet; the rest of its
/// period is idle (zero-length packets). Every packet of frame k carries the 60 MHz device
/// timestamp s * 7500 + k * 2,000,000 (mod 2^32), so frames are exactly 2,000,000 ticks apart.
/// The 8-bit sequence number of packet p of frame k is (k * N + p) mod 256: it restarts at 0 with
/// every stream start, and a dropped packet leaves a gap.
/// Not from hardware: the real device's SOF timestamp (reported as 0 on early captures), header
/// byte 4, and how sequence numbers continue across a restart are not modelled.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/rng.hpp"
#include "simulation/devices/sim_usb_device.hpp"  // USB_MICROFRAME_NS

namespace orthoflow::simulation {

inline constexpr std::uint32_t KINECT_FRAME_WIDTH = 640;
inline constexpr std::uint32_t KINECT_FRAME_HEIGHT = 480;
inline constexpr std::uint32_t KINECT_IR_HEIGHT = 488;  ///< "640x480" IR really is 640x488
inline constexpr std::size_t KINECT_ISO_HEADER_BYTES = 12;
inline constexpr std::size_t KINECT_DEPTH_PAYLOAD_BYTES = 1748;      ///< 1760 - 12
inline constexpr std::size_t KINECT_VIDEO_PAYLOAD_BYTES = 1908;      ///< 1920 - 12
inline constexpr std::size_t KINECT_ISO_MAX_PACKET_BYTES = 1920;     ///< 2 x 960 per microframe
inline constexpr std::uint32_t KINECT_TICKS_PER_MICROFRAME = 7'500;  ///< 60 MHz x 125 us
inline constexpr std::uint32_t KINECT_TICKS_PER_FRAME = 2'000'000;   ///< 60 MHz / 30 Hz

/// @brief What one iso endpoint sends. Depth (0x82): DEPTH_11BIT (reg 0x12 = 3), DEPTH_10BIT (2).
/// Video (0x81): BAYER (reg 0x05 = 1), IR_10BIT (reg 0x05 = 3, 640x488).
enum class SimStreamMode : std::uint8_t { OFF, DEPTH_11BIT, DEPTH_10BIT, BAYER, IR_10BIT };

/// @brief Bytes of one frame in @p mode (0 for OFF): 422400, 384000, 307200, 390400.
[[nodiscard]] std::size_t stream_frame_bytes(SimStreamMode mode) noexcept;
/// @brief Payload bytes per packet: 1748 for depth, 1908 for video and IR.
[[nodiscard]] std::size_t stream_payload_bytes(SimStreamMode mode) noexcept;
/// @brief Packets per frame, ceil(frame / payload): 242, 220, 162, 205.
[[nodiscard]] std::size_t stream_packets_per_frame(SimStreamMode mode) noexcept;

/// @brief Packs @p in, @p bits per value (1..16, the low bits of each value), as one MSB-first
/// bit stream (KINECT_V1.md 7.1: 11 bits -> 8 pixels in 11 bytes). A trailing partial byte is
/// zero-padded. @pre out.size() >= ceil(in.size() * bits / 8) (OF_ENFORCE).
/// @return bytes written. @note No allocation; deterministic.
std::size_t sim_pack_msb_first(std::span<const std::uint16_t> in, unsigned bits,
                               std::span<std::uint8_t> out) noexcept;

/// @brief Bus faults applied to generated packets; every rate in [0, 1], 0 = off.
struct SimPacketFaults {
  double drop_rate = 0.0;       ///< the packet never arrives (its sequence number is skipped)
  double duplicate_rate = 0.0;  ///< the packet arrives twice in consecutive microframes
  double corrupt_rate = 0.0;    ///< one byte of header or payload is XORed with a nonzero value
  double reorder_rate = 0.0;    ///< the packet and the next one of its frame arrive swapped
  /// Header bytes 6-7 (read as a packet size, KINECT_V1.md 13 row 11) are written as zero: a
  /// device that fills them differently from the brief's inference.
  bool size_field_zero = false;
};

/// @brief What a generator did since construction (all packets, faults counted per event).
struct SimStreamCounters {
  std::uint64_t frames_started = 0;     ///< frames whose first packet was generated
  std::uint64_t packets_generated = 0;  ///< nominal packets (before faults)
  std::uint64_t packets_emitted = 0;    ///< packets handed to the bus (duplicates included)
  std::uint64_t packets_dropped = 0;
  std::uint64_t packets_duplicated = 0;
  std::uint64_t packets_corrupted = 0;
  std::uint64_t packets_reordered = 0;  ///< swaps (each moves two packets)
};

/// @brief Fills the packed bytes of frame @p frame (stream_frame_bytes(mode) of them).
using SimFrameFill =
    std::function<void(SimStreamMode mode, std::uint64_t frame, std::span<std::uint8_t> packed)>;

/// @brief The packets of one iso endpoint on microframe time.
/// @note Not thread-safe. Deterministic given the call sequence and the Rng. Allocates only in
/// the constructor (two packed frame buffers of the largest mode).
class SimIsoStreamGenerator {
 public:
  /// @brief A stopped generator for stream nibble @p stream_flag (0x70 depth, 0x80 video) whose
  /// frames are produced by @p fill. @pre fill non-empty.
  SimIsoStreamGenerator(std::uint8_t stream_flag, SimFrameFill fill);

  /// @brief Starts @p mode with frame 0 at microframe @p start_microframe; restarts if running.
  /// @pre mode != OFF.
  void start(SimStreamMode mode, std::int64_t start_microframe) noexcept;
  /// @brief Stops from microframe @p stop_microframe on (microframes before it still send).
  void stop(std::int64_t stop_microframe) noexcept;
  /// @brief Stops at once and forgets queued packets (power loss).
  void reset() noexcept {
    running_ = false;
    count_ = 0;
  }
  /// @brief The mode sent now (OFF when stopped).
  [[nodiscard]] SimStreamMode mode() const noexcept {
    return running_ ? mode_ : SimStreamMode::OFF;
  }

  /// @brief Writes the device packet of microframe @p microframe into @p out and returns its
  /// length (0 = idle microframe). Call with increasing microframes; skipped ones are never sent.
  /// @pre out.size() >= KINECT_ISO_MAX_PACKET_BYTES. @note No allocation.
  std::size_t packet(std::int64_t microframe, const SimPacketFaults& faults, core::Rng& rng,
                     std::span<std::byte> out) noexcept;

  [[nodiscard]] const SimStreamCounters& counters() const noexcept { return counters_; }

 private:
  struct Pending {
    std::uint64_t frame = 0;
    std::uint32_t packet = 0;
    std::uint16_t corrupt_at = 0;
    std::uint8_t corrupt_xor = 0;  // 0: intact
  };
  static constexpr std::size_t QUEUE = 16;

  void generate(std::int64_t microframe, const SimPacketFaults& faults, core::Rng& rng) noexcept;
  void push(std::uint64_t frame, std::uint32_t packet, const SimPacketFaults& faults,
            core::Rng& rng) noexcept;
  void enqueue(const Pending& p) noexcept;
  std::size_t emit(const Pending& p, std::span<std::byte> out, bool zero_size) noexcept;
  void load(std::uint64_t frame) noexcept;

  std::uint8_t stream_flag_;
  SimFrameFill fill_;
  SimStreamMode mode_ = SimStreamMode::OFF;
  bool running_ = false;
  std::int64_t start_mf_ = 0;
  std::int64_t stop_mf_ = 0;
  std::array<std::vector<std::uint8_t>, 2> frames_;  // frame k lives in frames_[k % 2]
  std::array<std::uint64_t, 2> loaded_{~0ULL, ~0ULL};
  std::array<Pending, QUEUE> queue_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::uint64_t skip_frame_ = ~0ULL;  // a packet already sent early by a swap
  std::uint32_t skip_packet_ = 0;
  SimStreamCounters counters_{};
};

}  // namespace orthoflow::simulation
