// ForwardingTransport: transfers, iso streams and the event pump, forwarded with the handle mapped.
#include <utility>

#include "simulation/devices/forwarding_transport.hpp"

namespace orthoflow::simulation {

using drivers::UsbDeviceHandle;
using drivers::UsbError;

Result<std::size_t, UsbError> ForwardingTransport::control(const UsbDeviceHandle& handle,
                                                           const drivers::UsbControlSetup& setup,
                                                           std::span<std::byte> data,
                                                           drivers::UsbTimeout timeout) {
  SeamCall call = call_on(SeamOp::CONTROL, handle);
  call.setup = setup;
  call.data = data;
  call.timeout = timeout;
  on_call(call);
  auto bytes_result = inner_.control(inner_handle(handle), setup, data, timeout);
  if (bytes_result) call.bytes = *bytes_result;
  return finish(call, std::move(bytes_result));
}

Result<std::size_t, UsbError> ForwardingTransport::bulk(const UsbDeviceHandle& handle,
                                                        std::uint8_t endpoint,
                                                        std::span<std::byte> data,
                                                        drivers::UsbTimeout timeout) {
  SeamCall call = call_on(SeamOp::BULK, handle, endpoint);
  call.data = data;
  call.timeout = timeout;
  on_call(call);
  auto bytes_result = inner_.bulk(inner_handle(handle), endpoint, data, timeout);
  if (bytes_result) call.bytes = *bytes_result;
  return finish(call, std::move(bytes_result));
}

Result<std::size_t, UsbError> ForwardingTransport::interrupt(const UsbDeviceHandle& handle,
                                                             std::uint8_t endpoint,
                                                             std::span<std::byte> data,
                                                             drivers::UsbTimeout timeout) {
  SeamCall call = call_on(SeamOp::INTERRUPT, handle, endpoint);
  call.data = data;
  call.timeout = timeout;
  on_call(call);
  auto bytes_result = inner_.interrupt(inner_handle(handle), endpoint, data, timeout);
  if (bytes_result) call.bytes = *bytes_result;
  return finish(call, std::move(bytes_result));
}

Result<std::size_t, UsbError> ForwardingTransport::max_iso_packet_size(
    const UsbDeviceHandle& handle, std::uint8_t endpoint) {
  SeamCall call = call_on(SeamOp::MAX_ISO_PACKET_SIZE, handle, endpoint);
  on_call(call);
  auto size_result = inner_.max_iso_packet_size(inner_handle(handle), endpoint);
  if (size_result) call.bytes = *size_result;
  return finish(call, std::move(size_result));
}

Result<void, UsbError> ForwardingTransport::start_iso(const UsbDeviceHandle& handle,
                                                      std::uint8_t endpoint,
                                                      const drivers::UsbIsoConfig& config,
                                                      drivers::UsbIsoCallback on_packet) {
  SeamCall call = call_on(SeamOp::START_ISO, handle, endpoint);
  call.iso = &config;
  on_call(call);
  return finish(call,
                inner_.start_iso(inner_handle(handle), endpoint, config, std::move(on_packet)));
}

Result<void, UsbError> ForwardingTransport::stop_iso(const UsbDeviceHandle& handle,
                                                     std::uint8_t endpoint) {
  SeamCall call = call_on(SeamOp::STOP_ISO, handle, endpoint);
  on_call(call);
  return finish(call, inner_.stop_iso(inner_handle(handle), endpoint));
}

Result<drivers::UsbIsoStats, UsbError> ForwardingTransport::iso_stats(const UsbDeviceHandle& handle,
                                                                      std::uint8_t endpoint) const {
  SeamCall call = call_on(SeamOp::ISO_STATS, handle, endpoint);
  on_call(call);
  return finish(call, inner_.iso_stats(inner_handle(handle), endpoint));
}

Result<void, UsbError> ForwardingTransport::handle_events(drivers::UsbTimeout timeout) {
  SeamCall call;
  call.op = SeamOp::HANDLE_EVENTS;
  call.timeout = timeout;
  on_call(call);
  return finish(call, inner_.handle_events(timeout));
}

}  // namespace orthoflow::simulation
