// SimUsbTransport: isochronous streams, plug events and simulated time. Every state change of a
// device happens at one simulated instant, and packets are generated for a microframe only once
// that microframe has fully elapsed (fill() up to now before any control request reaches the
// device), so a register write takes effect exactly between two microframes.
#include <algorithm>
#include <climits>
#include <cstring>
#include <limits>

#include "core/assert.hpp"
#include "simulation/sim_usb_transport.hpp"
#include "simulation/sim_usb_transport_state.hpp"

namespace orthoflow::simulation {

using drivers::UsbError;
using drivers::UsbPacketStatus;

namespace {

constexpr std::size_t ISO_MAX_TRANSFERS = 1024;  // as LibusbTransport
constexpr std::int64_t NEVER = std::numeric_limits<std::int64_t>::max();

Unexpected<UsbError> refused(UsbError::Code code, const char* operation) {
  return orthoflow::err(UsbError{code, 0, operation});
}

bool valid_iso_request(std::uint8_t endpoint, const drivers::UsbIsoConfig& c,
                       const drivers::UsbIsoCallback& on_packet) {
  if ((endpoint & 0x80U) == 0 || !on_packet) return false;
  if (c.transfers == 0 || c.packets_per_transfer == 0 || c.packet_size == 0) return false;
  return c.transfers <= ISO_MAX_TRANSFERS && c.packets_per_transfer <= INT_MAX &&
         c.packet_size <= INT_MAX / c.packets_per_transfer;
}

}  // namespace

SimUsbTransport::Stream* SimUsbTransport::find_stream(std::uint32_t handle_id,
                                                      std::uint8_t endpoint) const noexcept {
  for (const auto& s : streams_) {
    if (s->handle == handle_id && s->endpoint == endpoint) return s.get();
  }
  return nullptr;
}

Result<void, UsbError> SimUsbTransport::start_iso(const drivers::UsbDeviceHandle& handle,
                                                  std::uint8_t endpoint,
                                                  const drivers::UsbIsoConfig& config,
                                                  drivers::UsbIsoCallback on_packet) {
  auto h_result = lookup(handle, "start_iso", true);
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  if (!valid_iso_request(endpoint, config, on_packet))
    return refused(UsbError::Code::INVALID_PARAM, "start_iso");
  const bool camera_endpoint =
      h.function == KinectFunction::CAMERA &&
      (endpoint == KINECT_VIDEO_ENDPOINT || endpoint == KINECT_DEPTH_ENDPOINT);
  const bool k4w_alt0 = slots_[h.kinect]->device->model() == KinectModel::K4W && h.alt != 1;
  if (!camera_endpoint || !h.claimed || k4w_alt0)
    return refused(UsbError::Code::NOT_FOUND, "start_iso");
  const bool busy = std::any_of(streams_.begin(), streams_.end(), [&](const auto& s) {
    return s->kinect == h.kinect && s->endpoint == endpoint;
  });
  if (busy) return refused(UsbError::Code::BUSY, "start_iso");
  auto s = std::make_unique<Stream>();
  s->handle = h.id;
  s->kinect = h.kinect;
  s->endpoint = endpoint;
  s->config = config;
  s->on_packet = std::move(on_packet);
  s->buffer.assign(config.transfers * config.packets_per_transfer * config.packet_size,
                   std::byte{0});
  s->lengths.assign(config.packets_per_transfer, 0);
  s->statuses.assign(config.packets_per_transfer, UsbPacketStatus::COMPLETED);
  // The first transfer is scheduled from the next microframe boundary on.
  s->first_mf = (clock_->now_ns() + USB_MICROFRAME_NS - 1) / USB_MICROFRAME_NS;
  s->stats.transfers_in_flight = config.transfers;
  streams_.push_back(std::move(s));
  return {};
}

Result<void, UsbError> SimUsbTransport::stop_iso(const drivers::UsbDeviceHandle& handle,
                                                 std::uint8_t endpoint) {
  auto h_result = lookup(handle, "stop_iso", false);
  if (!h_result) return orthoflow::err(h_result.error());
  const std::uint32_t id = (*h_result)->id;
  if (find_stream(id, endpoint) == nullptr) return refused(UsbError::Code::NOT_FOUND, "stop_iso");
  // Cancelled transfers come back at once in the simulator: nothing is delivered, nothing leaks.
  std::erase_if(streams_,
                [&](const auto& s) { return s->handle == id && s->endpoint == endpoint; });
  return {};
}

Result<drivers::UsbIsoStats, UsbError> SimUsbTransport::iso_stats(
    const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint) const {
  auto h_result = lookup(handle, "iso_stats", false);
  if (!h_result) return orthoflow::err(h_result.error());
  const Stream* s = find_stream((*h_result)->id, endpoint);
  if (s == nullptr) return refused(UsbError::Code::NOT_FOUND, "iso_stats");
  return s->stats;
}

Result<void, UsbError> SimUsbTransport::handle_events(drivers::UsbTimeout timeout) {
  enforce_not_in_callback();
  if (timeout.count() < 0) return refused(UsbError::Code::INVALID_PARAM, "handle_events");
  const std::int64_t now = clock_->now_ns();
  std::int64_t target = now;
  if (timeout.count() > 0) {
    const std::int64_t deadline = now + std::chrono::nanoseconds(timeout).count();
    target = std::clamp(next_event_ns(), now, deadline);
  }
  run_until(target);
  return {};
}

void SimUsbTransport::run_for(std::chrono::nanoseconds duration) {
  enforce_not_in_callback();
  OF_ENFORCE(duration.count() >= 0, "SimUsbTransport::run_for: negative duration");
  run_until(clock_->now_ns() + duration.count());
}

void SimUsbTransport::unplug(std::size_t index) {
  enforce_not_in_callback();
  OF_ENFORCE(index < slots_.size(), "SimUsbTransport::unplug: no such Kinect");
  run_until(clock_->now_ns());
  Slot& slot = *slots_[index];
  if (!slot.present) return;
  for (auto& s : streams_) {
    if (s->kinect == index && s->alive) fail_stream(*s, UsbPacketStatus::NO_DEVICE);
  }
  slot.present = false;
  slot.claimed_by = {};
  slot.device->power_cycle();
  slot.device->audio_power_on();
  slot.audio_generation = slot.device->audio_generation();
}

void SimUsbTransport::replug(std::size_t index) {
  enforce_not_in_callback();
  OF_ENFORCE(index < slots_.size(), "SimUsbTransport::replug: no such Kinect");
  Slot& slot = *slots_[index];
  if (slot.present) return;
  slot.present = true;
  ++slot.epoch;
  slot.gspca_bound = true;  // the kernel binds gspca_kinect again at plug-in
  slot.claimed_by = {};
  slot.device->power_cycle();
  slot.device->audio_power_on();
  slot.audio_generation = slot.device->audio_generation();
  assign_addresses(slot);
}

void SimUsbTransport::advance_clock(std::int64_t t_ns) noexcept {
  // A given clock may have been moved ahead by hand: events then run late, never backwards.
  if (t_ns > clock_->now_ns()) clock_->set_ns(t_ns);
}

std::int64_t SimUsbTransport::next_event_ns() const noexcept {
  std::int64_t next = NEVER;
  for (const auto& s : streams_) {
    if (s->alive && slots_[s->kinect]->present) next = std::min(next, s->completion_ns());
  }
  for (const auto& slot : slots_) {
    const SimKinectFaults& f = slot->device->faults();
    if (slot->present && !slot->disconnect_done && f.disconnect_at_ns)
      next = std::min(next, *f.disconnect_at_ns);
    if (!slot->present && !slot->reconnect_done && f.reconnect_at_ns)
      next = std::min(next, *f.reconnect_at_ns);
    if (slot->present && !slot->cancel_done && f.cancel_at_ns)
      next = std::min(next, *f.cancel_at_ns);
  }
  return next;
}

bool SimUsbTransport::run_next_event(std::int64_t limit_ns) {
  // Transfer completions first: on a tie they happened before the plug event.
  Stream* first = nullptr;
  for (const auto& s : streams_) {
    if (!s->alive || !slots_[s->kinect]->present) continue;
    if (first == nullptr || s->completion_ns() < first->completion_ns()) first = s.get();
  }
  const std::int64_t next = next_event_ns();
  if (next > limit_ns) return false;
  advance_clock(next);
  if (first != nullptr && first->completion_ns() == next) {
    complete(*first);
    return true;
  }
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    Slot& slot = *slots_[k];
    const SimKinectFaults& f = slot.device->faults();
    if (slot.present && !slot.disconnect_done && f.disconnect_at_ns == next) {
      slot.disconnect_done = true;
      unplug(k);
      return true;
    }
    if (!slot.present && !slot.reconnect_done && f.reconnect_at_ns == next) {
      slot.reconnect_done = true;
      replug(k);
      return true;
    }
    if (slot.present && !slot.cancel_done && f.cancel_at_ns == next) {
      slot.cancel_done = true;
      for (auto& s : streams_) {
        if (s->kinect == k && s->alive) fail_stream(*s, UsbPacketStatus::CANCELLED);
      }
      return true;
    }
  }
  return false;  // unreachable: next came from one of the sources above
}

void SimUsbTransport::run_until(std::int64_t target_ns) {
  while (run_next_event(target_ns)) {}
  advance_clock(target_ns);
}

void SimUsbTransport::sync_streams(std::int64_t now_ns) noexcept {
  for (auto& s : streams_) {
    if (s->alive) fill(*s, now_ns / USB_MICROFRAME_NS);
  }
}

void SimUsbTransport::fill(Stream& s, std::int64_t microframe_limit) noexcept {
  SimKinectDevice& device = *slots_[s.kinect]->device;
  const std::size_t packets = s.config.packets_per_transfer;
  const std::size_t size = s.config.packet_size;
  std::byte* base = s.buffer.data() + (s.completed % s.config.transfers) * packets * size;
  const bool direct = size >= KINECT_ISO_MAX_PACKET_BYTES;
  while (s.filled < packets &&
         s.first_mf + static_cast<std::int64_t>(s.filled) < microframe_limit) {
    std::byte* slot = base + s.filled * size;
    const std::span<std::byte> out =
        direct ? std::span<std::byte>(slot, size) : std::span<std::byte>(s.scratch);
    const std::int64_t mf = s.first_mf + static_cast<std::int64_t>(s.filled);
    std::size_t length = device.iso_packet(s.endpoint, mf, out);
    UsbPacketStatus status = UsbPacketStatus::COMPLETED;
    if (length > size) {
      status = UsbPacketStatus::OVERFLOW;
      length = 0;
    } else if (!direct && length > 0) {
      std::memcpy(slot, s.scratch.data(), length);
    }
    s.lengths[s.filled] = length;
    s.statuses[s.filled] = status;
    ++s.filled;
  }
}

void SimUsbTransport::complete(Stream& s) {
  const std::size_t packets = s.config.packets_per_transfer;
  const std::size_t size = s.config.packet_size;
  fill(s, s.first_mf + static_cast<std::int64_t>(packets));
  const std::byte* base = s.buffer.data() + (s.completed % s.config.transfers) * packets * size;
  ++s.stats.transfers_completed;  // per-packet statuses (OVERFLOW) do not fail the transfer
  in_callback_ = true;
  for (std::size_t i = 0; i < packets; ++i) {
    const bool ok = s.statuses[i] == UsbPacketStatus::COMPLETED;
    const std::size_t length = ok ? s.lengths[i] : 0;
    ++(ok ? s.stats.packets_completed : s.stats.packets_failed);
    s.stats.bytes_received += length;
    s.on_packet({base + i * size, length}, length, s.statuses[i]);
  }
  in_callback_ = false;
  ++s.completed;  // and resubmitted at once: it now covers the microframes after the newest one
  s.first_mf += static_cast<std::int64_t>(packets);
  s.filled = 0;
}

void SimUsbTransport::fail_stream(Stream& s, UsbPacketStatus status) {
  // Every in-flight transfer comes back whole with this status and is not resubmitted (what
  // LibusbTransport does for NO_DEVICE and for a CANCELLED it did not ask for).
  in_callback_ = true;
  for (std::size_t t = 0; t < s.stats.transfers_in_flight; ++t) {
    ++s.stats.transfers_failed;
    for (std::size_t i = 0; i < s.config.packets_per_transfer; ++i) {
      ++s.stats.packets_failed;
      s.on_packet({}, 0, status);
    }
  }
  in_callback_ = false;
  s.stats.transfers_in_flight = 0;
  s.alive = false;
}

}  // namespace orthoflow::simulation
