// SimUsbHost: control, bulk and interrupt transfers and their timing. The device answers; the host
// checks the handle, the claim and the endpoint, and takes the time (sim_usb_host.hpp).
#include <algorithm>
#include <array>
#include <climits>

#include "core/assert.hpp"
#include "simulation/devices/sim_usb_host.hpp"
#include "simulation/devices/sim_usb_host_state.hpp"

namespace orthoflow::simulation {

using drivers::UsbError;

namespace {

constexpr std::size_t CONTROL_MAX_BYTES = 65535;  // wLength

Unexpected<UsbError> refused(UsbError::Code code, const char* operation) {
  return orthoflow::err(UsbError{code, 0, operation});
}

}  // namespace

std::int64_t SimUsbHost::wait_ns(drivers::UsbTimeout timeout) const noexcept {
  const auto wait = timeout.count() == 0 ? config_.infinite_wait : timeout;
  return std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
}

Result<std::size_t, UsbError> SimUsbHost::finish_request(const Handle& h, SimControlReply reply,
                                                         drivers::UsbTimeout timeout,
                                                         const char* operation) {
  // The device answered at the start; the transfer takes its latency (or, stalled, its timeout)
  // with events pumped meanwhile, and an unplug on the way shows at the end.
  if (reply.outcome == SimControlOutcome::TIMEOUT) {
    run_until(clock_->now_ns() + wait_ns(timeout));
    return refused(UsbError::Code::TIMEOUT, operation);
  }
  run_until(clock_->now_ns() + config_.control_latency.count());
  if (!alive(h)) return refused(UsbError::Code::NO_DEVICE, operation);
  if (reply.outcome == SimControlOutcome::PIPE) return refused(UsbError::Code::PIPE, operation);
  return reply.bytes;
}

Result<std::size_t, UsbError> SimUsbHost::control(const drivers::UsbDeviceHandle& handle,
                                                  const drivers::UsbControlSetup& setup,
                                                  std::span<std::byte> data,
                                                  drivers::UsbTimeout timeout) {
  auto h_result = lookup(handle, "control", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > CONTROL_MAX_BYTES) return refused(UsbError::Code::INVALID_PARAM, "control");
  const Handle h = **h_result;  // a copy: callbacks cannot touch handles, but keep it simple
  SimUsbDevice& device = *slots_[h.slot]->device;
  const std::optional<SimEndpoint> ep0 = device.endpoint(h.function, 0);
  if (!ep0 || ep0->type != SimEndpointType::CONTROL)
    return refused(UsbError::Code::NOT_SUPPORTED, "control");
  run_until(clock_->now_ns());
  sync_streams(clock_->now_ns());
  if (!alive(h)) return refused(UsbError::Code::NO_DEVICE, "control");
  const SimControlReply reply = device.control(h.function, setup, data, clock_->now_ns());
  auto bytes_result = finish_request(h, reply, timeout, "control");
  if (!bytes_result) return bytes_result;
  const bool out = (setup.request_type & 0x80U) == 0;
  if (out && *bytes_result < data.size())
    return orthoflow::err(
        UsbError{UsbError::Code::SHORT_TRANSFER, static_cast<int>(*bytes_result), "control"});
  return bytes_result;
}

Result<std::size_t, UsbError> SimUsbHost::bulk(const drivers::UsbDeviceHandle& handle,
                                               std::uint8_t endpoint, std::span<std::byte> data,
                                               drivers::UsbTimeout timeout) {
  auto h_result = lookup(handle, "bulk", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > INT_MAX) return refused(UsbError::Code::INVALID_PARAM, "bulk");
  const Handle h = **h_result;
  if (!endpoint_of(h, endpoint, SimEndpointType::BULK))
    return refused(UsbError::Code::NOT_FOUND, "bulk");
  run_until(clock_->now_ns());
  sync_streams(clock_->now_ns());
  if (!alive(h)) return refused(UsbError::Code::NO_DEVICE, "bulk");
  SimUsbDevice& device = *slots_[h.slot]->device;
  const SimControlReply reply = device.bulk(h.function, endpoint, data, clock_->now_ns());
  return finish_request(h, reply, timeout, "bulk");
}

Result<std::size_t, UsbError> SimUsbHost::interrupt(const drivers::UsbDeviceHandle& handle,
                                                    std::uint8_t endpoint,
                                                    std::span<std::byte> data,
                                                    drivers::UsbTimeout timeout) {
  enforce_not_in_callback();
  run_until(clock_->now_ns());
  auto h_result = lookup(handle, "interrupt", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > INT_MAX) return refused(UsbError::Code::INVALID_PARAM, "interrupt");
  const Handle h = **h_result;  // a copy: run_until never touches handles, but keep it simple
  const std::optional<SimEndpoint> ep = endpoint_of(h, endpoint, SimEndpointType::INTERRUPT);
  if (!ep) return refused(UsbError::Code::NOT_FOUND, "interrupt");
  OF_ENFORCE(ep->max_packet <= SIM_USB_MAX_INTERRUPT_PACKET, "SimUsbHost: interrupt packet size");
  if ((endpoint & 0x80U) != 0) return interrupt_in(h, endpoint, data, timeout);
  if (ep->whole_packets && data.size() != ep->max_packet)
    return refused(UsbError::Code::INVALID_PARAM, "interrupt");  // nothing is sent
  if (!run_while_alive(h, clock_->now_ns() + config_.interrupt_latency.count()))
    return refused(UsbError::Code::NO_DEVICE, "interrupt");
  sync_streams(clock_->now_ns());
  slots_[h.slot]->device->interrupt_out(h.function, endpoint, data, clock_->now_ns());
  return data.size();
}

Result<std::size_t, UsbError> SimUsbHost::interrupt_in(const Handle& h, std::uint8_t endpoint,
                                                       std::span<std::byte> data,
                                                       drivers::UsbTimeout timeout) {
  SimUsbDevice& device = *slots_[h.slot]->device;
  if (!device.interrupt_pending(h.function, endpoint)) {
    if (!run_while_alive(h, clock_->now_ns() + wait_ns(timeout)))
      return refused(UsbError::Code::NO_DEVICE, "interrupt");
    return refused(UsbError::Code::TIMEOUT, "interrupt");
  }
  if (!run_while_alive(h, clock_->now_ns() + config_.interrupt_latency.count()))
    return refused(UsbError::Code::NO_DEVICE, "interrupt");
  std::array<std::byte, SIM_USB_MAX_INTERRUPT_PACKET> packet{};
  const std::size_t length = device.interrupt_in(h.function, endpoint, packet);
  if (data.size() < length) return refused(UsbError::Code::OVERFLOW, "interrupt");  // lost
  std::copy_n(packet.begin(), length, data.begin());
  return length;
}

}  // namespace orthoflow::simulation
