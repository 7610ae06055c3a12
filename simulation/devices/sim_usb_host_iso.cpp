// SimUsbHost: isochronous IN streams. Packets are generated for a microframe only once that
// microframe has fully elapsed (fill() up to now before any request reaches a device), so a
// register write takes effect exactly between two microframes.
#include <algorithm>
#include <climits>
#include <cstring>

#include "core/assert.hpp"
#include "simulation/devices/sim_usb_host.hpp"
#include "simulation/devices/sim_usb_host_state.hpp"

namespace orthoflow::simulation {

using drivers::UsbError;
using drivers::UsbPacketStatus;

namespace {

constexpr std::size_t ISO_MAX_TRANSFERS = 1024;  // as LibusbTransport

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

Result<void, UsbError> SimUsbHost::start_iso(const drivers::UsbDeviceHandle& handle,
                                             std::uint8_t endpoint,
                                             const drivers::UsbIsoConfig& config,
                                             drivers::UsbIsoCallback on_packet) {
  auto h_result = lookup(handle, "start_iso", true);
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  if (!valid_iso_request(endpoint, config, on_packet))
    return refused(UsbError::Code::INVALID_PARAM, "start_iso");
  const std::optional<SimEndpoint> ep = endpoint_of(h, endpoint, SimEndpointType::ISO);
  if (!ep || h.alt[ep->interface] != ep->alt_setting)
    return refused(UsbError::Code::NOT_FOUND, "start_iso");
  const bool busy = std::any_of(streams_.begin(), streams_.end(), [&](const auto& s) {
    return s->slot == h.slot && s->function == h.function && s->endpoint == endpoint;
  });
  if (busy) return refused(UsbError::Code::BUSY, "start_iso");
  auto s = std::make_unique<Stream>();
  s->handle = h.id;
  s->slot = h.slot;
  s->function = h.function;
  s->endpoint = endpoint;
  s->config = config;
  s->on_packet = std::move(on_packet);
  s->buffer.assign(config.transfers * config.packets_per_transfer * config.packet_size,
                   std::byte{0});
  s->lengths.assign(config.packets_per_transfer, 0);
  s->statuses.assign(config.packets_per_transfer, UsbPacketStatus::COMPLETED);
  if (config.packet_size < ep->max_packet) s->scratch.assign(ep->max_packet, std::byte{0});
  // The first transfer is scheduled from the next microframe boundary on.
  s->first_mf = (clock_->now_ns() + USB_MICROFRAME_NS - 1) / USB_MICROFRAME_NS;
  s->stats.transfers_in_flight = config.transfers;
  streams_.push_back(std::move(s));
  return {};
}

Result<void, UsbError> SimUsbHost::stop_iso(const drivers::UsbDeviceHandle& handle,
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

Result<drivers::UsbIsoStats, UsbError> SimUsbHost::iso_stats(const drivers::UsbDeviceHandle& handle,
                                                             std::uint8_t endpoint) const {
  auto h_result = lookup(handle, "iso_stats", false);
  if (!h_result) return orthoflow::err(h_result.error());
  const Stream* s = find_stream((*h_result)->id, endpoint);
  if (s == nullptr) return refused(UsbError::Code::NOT_FOUND, "iso_stats");
  return s->stats;
}

void SimUsbHost::sync_streams(std::int64_t now_ns) noexcept {
  for (auto& s : streams_) {
    if (s->alive) fill(*s, now_ns / USB_MICROFRAME_NS);
  }
}

void SimUsbHost::fill(Stream& s, std::int64_t microframe_limit) noexcept {
  SimUsbDevice& device = *slots_[s.slot]->device;
  const std::size_t packets = s.config.packets_per_transfer;
  const std::size_t size = s.config.packet_size;
  std::byte* base = s.buffer.data() + (s.completed % s.config.transfers) * packets * size;
  const bool direct = s.scratch.empty();  // packet slots hold the device's largest packet
  while (s.filled < packets &&
         s.first_mf + static_cast<std::int64_t>(s.filled) < microframe_limit) {
    std::byte* slot = base + s.filled * size;
    const std::span<std::byte> out =
        direct ? std::span<std::byte>(slot, size) : std::span<std::byte>(s.scratch);
    const std::int64_t mf = s.first_mf + static_cast<std::int64_t>(s.filled);
    std::size_t length = device.iso_packet(s.function, s.endpoint, mf, out);
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

void SimUsbHost::complete(Stream& s) {
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

void SimUsbHost::fail_streams(std::size_t slot, UsbPacketStatus status) {
  for (auto& s : streams_) {
    if (s->slot == slot && s->alive) fail_stream(*s, status);
  }
}

void SimUsbHost::fail_stream(Stream& s, UsbPacketStatus status) {
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
