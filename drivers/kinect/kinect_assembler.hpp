#pragma once
/// @file
/// @brief FrameAssembler: the Kinect v1 isochronous frame assembler as a state machine
/// (specs/KINECT_V1.md 6): 12-byte packet headers, SOF / MOF / EOF flags, 8-bit sequence numbers
/// with wrap, lost packets, resynchronisation, short and oversize payloads, and the 60 MHz device
/// timestamp unwrapped to 64 bits.
///
/// Where it departs from libfreenect (section 6.2), on purpose:
/// - A packet that arrives late (1..5 behind) fills its slot if the slot is still empty, instead of
///   forcing a resync; a repeat of a packet already placed is counted as a duplicate and dropped.
/// - A slot no packet filled is never left holding the previous frame's bytes: it is filled with
///   a marker (0xFF: "no reading" in the depth formats), the frame is delivered as incomplete with
///   its per-packet map, and the caller masks the pixels the hole touches (hole_pixel_ranges).
/// - The header's big-endian size field is cross-checked against the packet's length.
/// Untrusted input: every byte comes from the device (fuzzed in tests/fuzz).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace orthoflow::drivers::kinect {

inline constexpr std::size_t PACKET_HEADER_BYTES = 12;

/// @brief The packet layout of one stream mode.
struct StreamGeometry {
  std::uint8_t stream = 0x70;     ///< high nibble of the flag: 0x70 depth, 0x80 video / IR
  std::size_t frame_bytes = 0;    ///< bytes of a whole frame
  std::size_t payload_bytes = 0;  ///< data bytes per packet but the last (1748 depth, 1908 video)
  std::size_t packets = 0;        ///< packets per frame
  std::size_t last_payload = 0;   ///< data bytes of the last packet
  std::uint8_t hole_fill = 0xFF;  ///< byte written where no packet arrived
};
/// @brief Depth 640x480 packed in @p bits (11 or 10) bits per pixel: 242 / 220 packets.
[[nodiscard]] StreamGeometry depth_geometry(unsigned bits) noexcept;
/// @brief Video of @p frame_bytes (Bayer 640x480: 307200 bytes, 162 packets).
[[nodiscard]] StreamGeometry video_geometry(std::size_t frame_bytes) noexcept;

/// @brief A frame as the assembler hands it over. Views the assembler's buffer: valid only during
/// the sink call.
struct AssembledFrame {
  std::span<const std::uint8_t> bytes;           ///< frame_bytes, holes filled with hole_fill
  std::span<const std::uint8_t> packet_present;  ///< per packet slot: 1 if a packet filled it
  std::uint64_t device_ticks = 0;   ///< unwrapped 60 MHz device time of the frame's last packet
  std::int64_t host_ns = 0;         ///< host clock when the frame's last packet was seen
  std::uint64_t number = 0;         ///< frames delivered before this one on the stream
  std::size_t packets_present = 0;  ///< slots filled
  bool complete = false;            ///< every slot filled by a packet of the right size
};

/// @brief Health counters of one stream (STYLE rule 16).
struct AssemblerStats {
  std::uint64_t packets = 0;        ///< packets seen, empty ones included
  std::uint64_t empty_packets = 0;  ///< zero-length (idle microframes)
  std::uint64_t short_header = 0;   ///< 1..11 bytes
  std::uint64_t bad_magic = 0;      ///< not "RB"
  std::uint64_t wrong_stream = 0;   ///< flag of another stream
  /// Header bytes 6-7 (an inferred size field) disagree with the packet length: counted only, the
  /// packet is judged by its length as libfreenect judges it.
  std::uint64_t bad_size_field = 0;
  std::uint64_t unsynced = 0;           ///< dropped while waiting for a start of frame
  std::uint64_t lost_packets = 0;       ///< sequence gaps of 1..5 (the slots became holes)
  std::uint64_t late_packets = 0;       ///< arrived 1..5 behind and filled their empty slot
  std::uint64_t duplicates = 0;         ///< arrived behind for a slot already filled (dropped)
  std::uint64_t resyncs = 0;            ///< gaps over 5 or flag mismatches: sync dropped
  std::uint64_t flag_mismatches = 0;    ///< SOF / MOF / EOF at the wrong position
  std::uint64_t oversize = 0;           ///< more data than the slot holds (dropped, slot a hole)
  std::uint64_t undersize = 0;          ///< less data than the slot holds (kept, rest is a hole)
  std::uint64_t frames_complete = 0;    ///< delivered whole
  std::uint64_t frames_incomplete = 0;  ///< delivered with holes
  std::uint64_t frames_abandoned = 0;   ///< started but lost to a resync (never delivered)
};

/// @brief Reassembles one stream. Allocates its buffers at construction only.
/// @note Not thread-safe: one thread (the USB thread) pushes.
class FrameAssembler {
 public:
  using Sink = std::function<void(const AssembledFrame&)>;
  /// @brief An assembler for @p geometry delivering frames to @p sink. @pre packets >= 2,
  /// payload sizes > 0, (packets - 1) x payload + last == frame_bytes (OF_ENFORCE).
  FrameAssembler(const StreamGeometry& geometry, Sink sink);

  /// @brief Feeds one isochronous packet (all its received bytes) seen at host time @p host_ns.
  /// Calls the sink when this packet finishes a frame (EOF, or a gap running past the end).
  /// @note Never allocates.
  void push(std::span<const std::uint8_t> packet, std::int64_t host_ns) noexcept;
  /// @brief Forgets the frame in progress (counted as abandoned if it had packets) and waits for
  /// the next start of frame: after a stream restart or a device reopen. @pre none.
  void reset() noexcept;

  /// @brief The counters so far. @pre none.
  [[nodiscard]] const AssemblerStats& stats() const noexcept { return stats_; }
  /// @brief The layout this assembler expects. @pre none.
  [[nodiscard]] const StreamGeometry& geometry() const noexcept { return geometry_; }

 private:
  void begin_frame() noexcept;
  void finish_frame(std::int64_t host_ns) noexcept;
  void abandon() noexcept;
  [[nodiscard]] std::size_t slot_bytes(std::size_t slot) const noexcept;
  [[nodiscard]] std::uint8_t expected_kind(std::size_t slot) const noexcept;
  void place(std::size_t slot, std::span<const std::uint8_t> data, bool& full) noexcept;
  void take_timestamp(std::uint32_t ticks) noexcept;

  StreamGeometry geometry_;
  Sink sink_;
  std::vector<std::uint8_t> frame_;
  std::vector<std::uint8_t> present_;
  std::size_t present_count_ = 0;
  std::size_t full_count_ = 0;  // slots filled with exactly their size
  bool synced_ = false;
  std::uint8_t expected_seq_ = 0;
  std::size_t slot_ = 0;  // the next slot to fill
  bool have_ticks_ = false;
  std::uint32_t last_ticks_ = 0;
  std::uint64_t unwrapped_ticks_ = 0;
  std::uint64_t frame_ticks_ = 0;
  std::uint64_t delivered_ = 0;
  std::int64_t last_host_ns_ = 0;
  AssemblerStats stats_{};
};

/// @brief A run of pixels [begin, end) touched by a hole.
struct PixelRange {
  std::size_t begin = 0;
  std::size_t end = 0;
};
/// @brief Calls @p mark(PixelRange) for every pixel range of a packed frame (@p bits per pixel,
/// @p pixels in all) that overlaps a slot without its whole packet: those pixels hold marker
/// bits, not data. One range per hole slot. @note Never allocates.
template <class Mark>
void for_each_hole_pixels(const AssembledFrame& frame, const StreamGeometry& geometry,
                          unsigned bits, std::size_t pixels, Mark&& mark) {
  for (std::size_t s = 0; s < frame.packet_present.size(); ++s) {
    if (frame.packet_present[s] != 0) continue;
    const std::size_t first_byte = s * geometry.payload_bytes;
    const std::size_t end_byte =
        first_byte + (s + 1 == geometry.packets ? geometry.last_payload : geometry.payload_bytes);
    // A pixel is touched if any of its bits lies in [first_byte * 8, end_byte * 8).
    const std::size_t begin = first_byte * 8 / bits;
    const std::size_t end = std::min(pixels, (end_byte * 8 + bits - 1) / bits);
    if (begin < end) mark(PixelRange{begin, end});
  }
}

}  // namespace orthoflow::drivers::kinect
