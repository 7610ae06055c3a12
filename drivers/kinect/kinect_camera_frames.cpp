// KinectCamera's frame path, run on the USB thread from the isochronous callbacks: assembled frames
// are decoded, paired with colour and published through the triple buffer. Nothing here allocates
// or blocks. (The control path, open / start / stop / pump / reopen, is in kinect_camera.cpp.)
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "kernels/packed_depth.hpp"

namespace orthoflow::drivers::kinect {

void KinectCamera::on_packet(std::span<const std::byte> bytes, UsbPacketStatus status,
                             FrameAssembler& assembler) noexcept {
  if (status != UsbPacketStatus::COMPLETED) {
    ++local_.iso_errors;
    // NO_DEVICE is an unplug; a CANCELLED nobody asked for is how some platforms report one.
    if (status == UsbPacketStatus::NO_DEVICE || status == UsbPacketStatus::CANCELLED) lost_ = true;
    return;
  }
  assembler.push(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
                 transport_->clock().now_ns());
}

void decode_depth(const AssembledFrame& frame, const StreamGeometry& geometry, DepthFormat format,
                  std::span<std::uint16_t> raw, bool scalar) noexcept {
  const bool eleven = format == DepthFormat::BITS_11;
  if (eleven) {
    scalar ? kernels::unpack_11bit_scalar(frame.bytes, raw)
           : kernels::unpack_11bit(frame.bytes, raw);
  } else {
    scalar ? kernels::unpack_10bit_scalar(frame.bytes, raw)
           : kernels::unpack_10bit(frame.bytes, raw);
  }
  if (frame.complete) return;
  // Pixels whose bits fall in a missing packet hold marker bits: make them "no reading".
  for_each_hole_pixels(frame, geometry, eleven ? 11U : 10U, raw.size(), [&](PixelRange r) {
    std::fill(raw.begin() + static_cast<std::ptrdiff_t>(r.begin),
              raw.begin() + static_cast<std::ptrdiff_t>(r.end), RAW_NO_READING);
  });
}

void KinectCamera::on_frame(const AssembledFrame& frame) noexcept {
  const auto& g = assembler_->geometry();
  const std::size_t missing = g.packets - frame.packets_present;
  if (missing > options_.max_missing_packets) {
    ++local_.frames_dropped;
    return;
  }
  if (pending_) {  // the previous depth frame never found its colour frame
    ++local_.depth_unpaired;
    publish_depth();
  }
  DepthFrame& slot = slots_[back_];
  decode_depth(frame, g, options_.depth_format, slot.raw);
  if (!frame.complete) ++local_.frames_degraded;
  slot.device_ticks = frame.device_ticks;
  slot.host_ns = frame.host_ns;
  slot.number = frame.number;
  slot.missing_packets = static_cast<std::uint32_t>(missing);
  slot.complete = frame.complete;
  slot.has_colour = false;
  if (!colour_assembler_) {
    publish_depth();
    return;
  }
  if (pair_with_ring(slot)) {
    publish_depth();
  } else {
    pending_ = true;  // the colour frame may still be on its way: the next one decides
  }
}

namespace {
/// Signed difference of two device times, modulo 2^32: the two streams unwrap independently.
std::int64_t tick_gap(std::uint64_t a, std::uint64_t b) noexcept {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a - b));
}
}  // namespace

void KinectCamera::attach_colour(DepthFrame& slot, std::size_t ring_index) noexcept {
  ColourSlot& c = colour_ring_[ring_index];
  slot.bayer.swap(c.bayer);  // same sizes: the ring slot, now used, takes the old buffer
  slot.has_colour = true;
  slot.colour_ticks = c.ticks;
  slot.colour_complete = c.complete;
  c.used = true;
  ++local_.frames_paired;
}

bool KinectCamera::pair_with_ring(DepthFrame& slot) noexcept {
  std::size_t best = colour_ring_.size();
  std::int64_t best_gap = options_.pair_tolerance_ticks + 1;
  for (std::size_t i = 0; i < colour_ring_.size(); ++i) {
    const ColourSlot& c = colour_ring_[i];
    if (!c.valid || c.used) continue;
    const std::int64_t gap = std::abs(tick_gap(c.ticks, slot.device_ticks));
    if (gap < best_gap) {
      best = i;
      best_gap = gap;
    }
  }
  if (best == colour_ring_.size()) return false;
  attach_colour(slot, best);
  return true;
}

void KinectCamera::on_colour(const AssembledFrame& frame) noexcept {
  const auto& g = colour_assembler_->geometry();
  if (g.packets - frame.packets_present > options_.max_missing_colour_packets) {
    ++local_.colour_dropped;
    return;
  }
  ColourSlot& c = colour_ring_[colour_next_];
  colour_next_ = (colour_next_ + 1) % colour_ring_.size();
  if (c.valid && !c.used) ++local_.colour_unpaired;
  std::memcpy(c.bayer.data(), frame.bytes.data(), c.bayer.size());
  c.ticks = frame.device_ticks;
  c.valid = true;
  c.used = false;
  c.complete = frame.complete;
  if (!pending_) return;
  DepthFrame& slot = slots_[back_];
  const std::int64_t gap = tick_gap(c.ticks, slot.device_ticks);
  if (std::abs(gap) <= options_.pair_tolerance_ticks) {
    attach_colour(slot, (colour_next_ + colour_ring_.size() - 1) % colour_ring_.size());
    publish_depth();
  } else if (gap > options_.pair_tolerance_ticks) {
    ++local_.depth_unpaired;  // colour moved past it: this depth frame has no partner
    publish_depth();
  }
}

void KinectCamera::reset_pairing() noexcept {
  if (pending_) {
    ++local_.depth_unpaired;
    publish_depth();
  }
  for (ColourSlot& c : colour_ring_) c.valid = false;
}

void KinectCamera::publish_depth() noexcept {
  pending_ = false;
  const DepthFrame& slot = slots_[back_];
  const std::uint8_t previous =
      state_.exchange(static_cast<std::uint8_t>(back_ | FRESH), std::memory_order_acq_rel);
  if ((previous & FRESH) != 0) ++local_.frames_overwritten;
  back_ = previous & 0x3U;
  ++local_.frames_delivered;
  local_.last_frame_host_ns = slot.host_ns;
}

std::array<HealthCounter, HEALTH_COUNTERS> health_counters(const CameraHealth& h) noexcept {
  const AssemblerStats& d = h.depth;
  return {{{"frames_delivered", h.frames_delivered},
           {"frames_degraded", h.frames_degraded},
           {"frames_dropped", h.frames_dropped},
           {"frames_not_taken", h.frames_overwritten},
           {"frames_abandoned", d.frames_abandoned},
           {"packets", d.packets},
           {"lost_packets", d.lost_packets},
           {"late_packets", d.late_packets},
           {"duplicate_packets", d.duplicates},
           {"bad_packets", d.bad_magic + d.short_header + d.wrong_stream + d.oversize},
           {"size_field_mismatch", d.bad_size_field},
           {"resyncs", d.resyncs},
           {"iso_errors", h.iso_errors},
           {"control_retries", h.control.retries},
           {"control_timeouts", h.control.timeouts},
           {"watchdog_restarts", h.watchdog_restarts},
           {"unplugs", h.unplugs},
           {"reopens", h.reopens},
           {"streaming", h.streaming ? 1U : 0U},
           {"device_lost", h.device_lost ? 1U : 0U}}};
}

const DepthFrame* KinectCamera::latest_depth() noexcept {
  if ((state_.load(std::memory_order_acquire) & FRESH) == 0) return nullptr;
  const std::uint8_t previous = state_.exchange(front_, std::memory_order_acq_rel);
  front_ = previous & 0x3U;
  return &slots_[front_];
}

CameraHealth KinectCamera::health() const noexcept {
  std::lock_guard<core::SpinLock> lock(health_lock_);
  return shared_;
}

void KinectCamera::publish_health() noexcept {
  local_.depth = assembler_->stats();
  if (colour_assembler_) local_.colour = colour_assembler_->stats();
  if (control_) local_.control = control_->stats();
  local_.streaming = streaming_;
  local_.device_lost = lost_;
  std::lock_guard<core::SpinLock> lock(health_lock_);
  shared_ = local_;
}

}  // namespace orthoflow::drivers::kinect
