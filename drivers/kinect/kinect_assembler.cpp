#include "drivers/kinect/kinect_assembler.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include "core/assert.hpp"

namespace orthoflow::drivers::kinect {

namespace {

constexpr std::uint8_t SOF = 0x1;
constexpr std::uint8_t MOF = 0x2;
constexpr std::uint8_t EOF_ = 0x5;
constexpr std::size_t MAX_GAP = 5;  // libfreenect's limit before it drops synchronisation

StreamGeometry geometry_for(std::uint8_t stream, std::size_t frame_bytes, std::size_t payload,
                            std::uint8_t fill) noexcept {
  StreamGeometry g;
  g.stream = stream;
  g.frame_bytes = frame_bytes;
  g.payload_bytes = payload;
  g.packets = (frame_bytes + payload - 1) / payload;
  g.last_payload = frame_bytes - (g.packets - 1) * payload;
  g.hole_fill = fill;
  return g;
}

}  // namespace

StreamGeometry depth_geometry(unsigned bits) noexcept {
  return geometry_for(0x70, 640 * 480 * bits / 8, 1748, 0xFF);
}

StreamGeometry video_geometry(std::size_t frame_bytes) noexcept {
  return geometry_for(0x80, frame_bytes, 1908, 0x00);
}

FrameAssembler::FrameAssembler(const StreamGeometry& geometry, Sink sink)
    : geometry_(geometry), sink_(std::move(sink)) {
  OF_ENFORCE(geometry.packets >= 2 && geometry.payload_bytes > 0 && geometry.last_payload > 0 &&
                 geometry.last_payload <= geometry.payload_bytes &&
                 (geometry.packets - 1) * geometry.payload_bytes + geometry.last_payload ==
                     geometry.frame_bytes,
             "FrameAssembler: inconsistent stream geometry");
  OF_ENFORCE(static_cast<bool>(sink_), "FrameAssembler: no sink");
  frame_.assign(geometry.frame_bytes, geometry.hole_fill);
  present_.assign(geometry.packets, 0);
}

std::size_t FrameAssembler::slot_bytes(std::size_t slot) const noexcept {
  return slot + 1 == geometry_.packets ? geometry_.last_payload : geometry_.payload_bytes;
}

std::uint8_t FrameAssembler::expected_kind(std::size_t slot) const noexcept {
  if (slot == 0) return SOF;
  return slot + 1 == geometry_.packets ? EOF_ : MOF;
}

void FrameAssembler::begin_frame() noexcept {
  std::fill(present_.begin(), present_.end(), std::uint8_t{0});
  present_count_ = 0;
  full_count_ = 0;
  slot_ = 0;
}

void FrameAssembler::abandon() noexcept {
  if (present_count_ > 0) ++stats_.frames_abandoned;
  begin_frame();
}

void FrameAssembler::reset() noexcept {
  abandon();
  synced_ = false;
}

void FrameAssembler::take_timestamp(std::uint32_t ticks) noexcept {
  if (!have_ticks_) {
    have_ticks_ = true;
    unwrapped_ticks_ = ticks;
  } else {
    unwrapped_ticks_ += static_cast<std::uint32_t>(ticks - last_ticks_);  // mod 2^32: wraps ~71 s
  }
  last_ticks_ = ticks;
  frame_ticks_ = unwrapped_ticks_;
}

void FrameAssembler::place(std::size_t slot, std::span<const std::uint8_t> data,
                           bool& full) noexcept {
  const std::size_t want = slot_bytes(slot);
  full = false;
  if (data.size() > want) {
    ++stats_.oversize;  // the slot stays a hole
    return;
  }
  std::uint8_t* dst = frame_.data() + slot * geometry_.payload_bytes;
  std::memcpy(dst, data.data(), data.size());
  if (data.size() < want) {
    ++stats_.undersize;
    std::memset(dst + data.size(), geometry_.hole_fill, want - data.size());
  }
  full = data.size() == want;
  present_[slot] = full ? 1 : 0;
  ++present_count_;
  if (full) ++full_count_;
}

void FrameAssembler::finish_frame(std::int64_t host_ns) noexcept {
  // Every slot no whole packet filled gets the marker: never the previous frame's bytes.
  for (std::size_t s = 0; s < geometry_.packets; ++s) {
    if (present_[s] == 0) {
      std::memset(frame_.data() + s * geometry_.payload_bytes, geometry_.hole_fill, slot_bytes(s));
    }
  }
  AssembledFrame out;
  out.bytes = frame_;
  out.packet_present = present_;
  out.device_ticks = frame_ticks_;
  out.host_ns = host_ns;
  out.number = delivered_++;
  out.packets_present = full_count_;
  out.complete = full_count_ == geometry_.packets;
  if (out.complete) {
    ++stats_.frames_complete;
  } else {
    ++stats_.frames_incomplete;
  }
  sink_(out);
  begin_frame();
}

void FrameAssembler::push(std::span<const std::uint8_t> packet, std::int64_t host_ns) noexcept {
  ++stats_.packets;
  last_host_ns_ = host_ns;
  if (packet.empty()) {
    ++stats_.empty_packets;
    return;
  }
  if (packet.size() < PACKET_HEADER_BYTES) {
    ++stats_.short_header;
    return;
  }
  if (packet[0] != 0x52 || packet[1] != 0x42) {
    ++stats_.bad_magic;
    return;
  }
  const std::uint8_t flag = packet[3];
  if ((flag & 0xF0U) != geometry_.stream) {
    ++stats_.wrong_stream;
    return;
  }
  // Bytes 6-7 as a packet size are inferred (KINECT_V1.md 13, row 11) and libfreenect ignores
  // them: a disagreement is counted, never a reason to drop (the length checks below decide).
  const std::size_t size_field = (std::size_t{packet[6]} << 8U) | packet[7];
  if (size_field != packet.size()) ++stats_.bad_size_field;
  const std::uint8_t kind = flag & 0x0FU;
  const std::uint8_t seq = packet[5];
  const std::uint32_t ticks = static_cast<std::uint32_t>(packet[8]) |
                              (static_cast<std::uint32_t>(packet[9]) << 8U) |
                              (static_cast<std::uint32_t>(packet[10]) << 16U) |
                              (static_cast<std::uint32_t>(packet[11]) << 24U);
  const auto data = packet.subspan(PACKET_HEADER_BYTES);

  if (!synced_) {
    if (kind != SOF) {
      ++stats_.unsynced;
      return;
    }
    synced_ = true;
    expected_seq_ = seq;
    begin_frame();
  }

  const auto ahead = static_cast<std::uint8_t>(seq - expected_seq_);
  if (ahead != 0) {
    const auto behind = static_cast<std::uint8_t>(expected_seq_ - seq);
    if (behind >= 1 && behind <= MAX_GAP) {
      // Late or repeated: it belongs to a slot already passed in this frame.
      if (behind <= slot_) {
        const std::size_t s = slot_ - behind;
        if (present_[s] == 0 && kind == expected_kind(s)) {
          bool full = false;
          place(s, data, full);
          ++stats_.late_packets;
          return;
        }
      }
      ++stats_.duplicates;
      return;
    }
    if (ahead > MAX_GAP) {
      ++stats_.resyncs;
      abandon();
      synced_ = false;
      if (kind != SOF) return;
      synced_ = true;  // this packet starts a frame: resynchronise on it at once
      expected_seq_ = seq;
    } else {
      stats_.lost_packets += ahead;
      expected_seq_ = seq;
      const std::size_t remaining = geometry_.packets - slot_;
      if (ahead >= remaining) {
        // The gap ran over the end of the frame: hand over what we have, with its holes.
        if (present_count_ > 0) {
          finish_frame(last_host_ns_);
        } else {
          begin_frame();
        }
        slot_ = ahead - remaining;
      } else {
        slot_ += ahead;
      }
    }
  }

  if (slot_ >= geometry_.packets || kind != expected_kind(slot_)) {
    ++stats_.flag_mismatches;
    ++stats_.resyncs;
    abandon();
    synced_ = false;
    if (kind != SOF) return;
    synced_ = true;
    expected_seq_ = seq;
  }

  bool full = false;
  place(slot_, data, full);
  if (kind != SOF) take_timestamp(ticks);  // SOF packets carry 0 on real devices (KINECT_V1.md 6)
  expected_seq_ = static_cast<std::uint8_t>(seq + 1);
  if (kind == EOF_) {
    finish_frame(host_ns);
  } else {
    ++slot_;
  }
}

}  // namespace orthoflow::drivers::kinect
