// SimIsoStreamGenerator: frames -> Kinect v1 iso packets (KINECT_V1.md 6), and the simulator's own
// MSB-first packer (7.1, 7.2). The packer is deliberately not kernels::pack_bits: the driver's
// unpacker is tested against an independent implementation.
#include "simulation/devices/sim_kinect_stream.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include "core/assert.hpp"

namespace orthoflow::simulation {

namespace {

constexpr std::uint8_t FLAG_SOF = 0x1;
constexpr std::uint8_t FLAG_MOF = 0x2;
constexpr std::uint8_t FLAG_EOF = 0x5;
constexpr std::size_t MAX_FRAME_BYTES = 422'400;  // 11-bit depth, the largest mode simulated

// First microframe of frame k, relative to the stream start: 8000 / 30 = 266.67 microframes.
std::int64_t frame_offset(std::uint64_t k) noexcept {
  return static_cast<std::int64_t>((k * 800) / 3);
}

bool hit(double rate, core::Rng& rng) noexcept { return rate > 0.0 && rng.uniform() < rate; }

}  // namespace

std::size_t stream_frame_bytes(SimStreamMode mode) noexcept {
  constexpr std::size_t PIXELS = std::size_t{KINECT_FRAME_WIDTH} * KINECT_FRAME_HEIGHT;
  switch (mode) {
    case SimStreamMode::DEPTH_11BIT:
      return PIXELS * 11 / 8;
    case SimStreamMode::DEPTH_10BIT:
      return PIXELS * 10 / 8;
    case SimStreamMode::BAYER:
      return PIXELS;
    case SimStreamMode::IR_10BIT:
      return std::size_t{KINECT_FRAME_WIDTH} * KINECT_IR_HEIGHT * 10 / 8;
    case SimStreamMode::OFF:
      break;
  }
  return 0;
}

std::size_t stream_payload_bytes(SimStreamMode mode) noexcept {
  return mode == SimStreamMode::DEPTH_11BIT || mode == SimStreamMode::DEPTH_10BIT
             ? KINECT_DEPTH_PAYLOAD_BYTES
             : KINECT_VIDEO_PAYLOAD_BYTES;
}

std::size_t stream_packets_per_frame(SimStreamMode mode) noexcept {
  const std::size_t payload = stream_payload_bytes(mode);
  return (stream_frame_bytes(mode) + payload - 1) / payload;
}

std::size_t sim_pack_msb_first(std::span<const std::uint16_t> in, unsigned bits,
                               std::span<std::uint8_t> out) noexcept {
  OF_ENFORCE(bits >= 1 && bits <= 16, "sim_pack_msb_first: bits must be 1..16");
  const std::size_t bytes = (in.size() * bits + 7) / 8;
  OF_ENFORCE(out.size() >= bytes, "sim_pack_msb_first: output too small");
  // A 32-bit accumulator: at most 7 pending bits plus 16 new ones.
  std::uint32_t acc = 0;
  unsigned pending = 0;
  std::size_t o = 0;
  const std::uint32_t mask = (1U << bits) - 1U;
  for (const std::uint16_t v : in) {
    acc = (acc << bits) | (v & mask);
    pending += bits;
    while (pending >= 8) {
      pending -= 8;
      out[o++] = static_cast<std::uint8_t>(acc >> pending);
    }
    acc &= (1U << pending) - 1U;
  }
  if (pending > 0) out[o++] = static_cast<std::uint8_t>(acc << (8 - pending));
  return o;
}

SimIsoStreamGenerator::SimIsoStreamGenerator(std::uint8_t stream_flag, SimFrameFill fill)
    : stream_flag_(stream_flag), fill_(std::move(fill)) {
  OF_ENFORCE(static_cast<bool>(fill_), "SimIsoStreamGenerator: a frame source is required");
  for (auto& f : frames_) f.assign(MAX_FRAME_BYTES, 0);
}

void SimIsoStreamGenerator::start(SimStreamMode mode, std::int64_t start_microframe) noexcept {
  OF_ENFORCE(mode != SimStreamMode::OFF, "SimIsoStreamGenerator::start: mode OFF");
  mode_ = mode;
  running_ = true;
  start_mf_ = start_microframe;
  stop_mf_ = INT64_MAX;
  loaded_ = {~0ULL, ~0ULL};  // a restart renders frame 0 again
  count_ = 0;
  skip_frame_ = ~0ULL;
}

void SimIsoStreamGenerator::stop(std::int64_t stop_microframe) noexcept {
  if (running_) stop_mf_ = std::max(stop_microframe, start_mf_);
}

std::size_t SimIsoStreamGenerator::packet(std::int64_t microframe, const SimPacketFaults& faults,
                                          core::Rng& rng, std::span<std::byte> out) noexcept {
  OF_ASSERT(out.size() >= KINECT_ISO_MAX_PACKET_BYTES, "packet: output smaller than 1920 bytes");
  if (!running_) return 0;
  if (microframe >= stop_mf_) {
    // The stop register ends the stream at once: queued duplicates and swaps are gone too.
    running_ = false;
    count_ = 0;
    return 0;
  }
  if (microframe >= start_mf_) generate(microframe, faults, rng);
  if (count_ == 0) return 0;
  const Pending p = queue_[head_];
  head_ = (head_ + 1) % QUEUE;
  --count_;
  return emit(p, out, faults.size_field_zero);
}

void SimIsoStreamGenerator::generate(std::int64_t microframe, const SimPacketFaults& faults,
                                     core::Rng& rng) noexcept {
  const auto d = static_cast<std::uint64_t>(microframe - start_mf_);
  std::uint64_t k = d * 3 / 800;
  if (frame_offset(k + 1) <= static_cast<std::int64_t>(d)) ++k;
  const auto p = static_cast<std::uint32_t>(d - static_cast<std::uint64_t>(frame_offset(k)));
  const auto n = static_cast<std::uint32_t>(stream_packets_per_frame(mode_));
  if (p >= n) return;  // idle tail of the frame period
  if (k == skip_frame_ && p == skip_packet_) {
    skip_frame_ = ~0ULL;  // already sent one microframe early by a swap
    return;
  }
  ++counters_.packets_generated;
  if (p == 0) ++counters_.frames_started;
  if (p + 1 < n && hit(faults.reorder_rate, rng)) {
    ++counters_.packets_reordered;
    ++counters_.packets_generated;
    push(k, p + 1, faults, rng);
    push(k, p, faults, rng);
    skip_frame_ = k;
    skip_packet_ = p + 1;
    return;
  }
  push(k, p, faults, rng);
}

void SimIsoStreamGenerator::push(std::uint64_t frame, std::uint32_t packet,
                                 const SimPacketFaults& faults, core::Rng& rng) noexcept {
  if (hit(faults.drop_rate, rng)) {
    ++counters_.packets_dropped;
    return;
  }
  Pending p{frame, packet, 0, 0};
  if (hit(faults.corrupt_rate, rng)) {
    ++counters_.packets_corrupted;
    const std::size_t payload = stream_payload_bytes(mode_);
    p.corrupt_at = static_cast<std::uint16_t>(
        rng.below(KINECT_ISO_HEADER_BYTES + std::min<std::size_t>(payload, 1132)));
    p.corrupt_xor = static_cast<std::uint8_t>(1 + rng.below(255));
  }
  enqueue(p);
  if (hit(faults.duplicate_rate, rng)) {
    ++counters_.packets_duplicated;
    enqueue(p);
  }
}

void SimIsoStreamGenerator::enqueue(const Pending& p) noexcept {
  if (count_ == QUEUE) {
    ++counters_.packets_dropped;  // the device's FIFO overflows: only with absurd duplicate rates
    return;
  }
  queue_[(head_ + count_) % QUEUE] = p;
  ++count_;
}

void SimIsoStreamGenerator::load(std::uint64_t frame) noexcept {
  auto& slot = frames_[frame % 2];
  if (loaded_[frame % 2] == frame) return;
  fill_(mode_, frame, std::span<std::uint8_t>(slot.data(), stream_frame_bytes(mode_)));
  loaded_[frame % 2] = frame;
}

std::size_t SimIsoStreamGenerator::emit(const Pending& p, std::span<std::byte> out,
                                        bool zero_size) noexcept {
  load(p.frame);
  const std::size_t frame_bytes = stream_frame_bytes(mode_);
  const std::size_t payload = stream_payload_bytes(mode_);
  const auto n = static_cast<std::uint32_t>(stream_packets_per_frame(mode_));
  const std::size_t offset = std::size_t{p.packet} * payload;
  const std::size_t data = std::min(payload, frame_bytes - offset);
  const std::size_t total = KINECT_ISO_HEADER_BYTES + data;
  const std::uint8_t kind = p.packet == 0 ? FLAG_SOF : (p.packet + 1 == n ? FLAG_EOF : FLAG_MOF);
  const auto seq = static_cast<std::uint8_t>((p.frame * n + p.packet) & 0xFFU);
  const auto ticks = static_cast<std::uint32_t>(static_cast<std::uint64_t>(start_mf_) *
                                                    KINECT_TICKS_PER_MICROFRAME +
                                                p.frame * KINECT_TICKS_PER_FRAME);
  const std::uint8_t header[KINECT_ISO_HEADER_BYTES] = {
      0x52,
      0x42,
      0x00,
      static_cast<std::uint8_t>(stream_flag_ | kind),
      0x00,
      seq,
      static_cast<std::uint8_t>(zero_size ? 0U : total >> 8),
      static_cast<std::uint8_t>(zero_size ? 0U : total & 0xFFU),
      static_cast<std::uint8_t>(ticks & 0xFFU),
      static_cast<std::uint8_t>((ticks >> 8) & 0xFFU),
      static_cast<std::uint8_t>((ticks >> 16) & 0xFFU),
      static_cast<std::uint8_t>(ticks >> 24)};
  std::memcpy(out.data(), header, sizeof(header));
  std::memcpy(out.data() + KINECT_ISO_HEADER_BYTES, frames_[p.frame % 2].data() + offset, data);
  if (p.corrupt_xor != 0) {
    const std::size_t at = std::min<std::size_t>(p.corrupt_at, total - 1);
    out[at] ^= std::byte{p.corrupt_xor};
  }
  ++counters_.packets_emitted;
  return total;
}

}  // namespace orthoflow::simulation
