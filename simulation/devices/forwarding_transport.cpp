// ForwardingTransport: every seam call forwarded to the inner transport with the handle mapped,
// shown to on_call() before and after.
#include "simulation/devices/forwarding_transport.hpp"

#include <utility>

namespace orthoflow::simulation {

using drivers::UsbDeviceHandle;
using drivers::UsbError;

const char* to_string(SeamOp op) noexcept {
  static constexpr const char* NAMES[] = {"enumerate",
                                          "open",
                                          "close",
                                          "claim_interface",
                                          "release_interface",
                                          "set_alt_setting",
                                          "kernel_driver_active",
                                          "detach_kernel_driver",
                                          "attach_kernel_driver",
                                          "reset_device",
                                          "clear_halt",
                                          "control",
                                          "bulk",
                                          "interrupt",
                                          "max_iso_packet_size",
                                          "start_iso",
                                          "stop_iso",
                                          "iso_stats",
                                          "handle_events"};
  const auto index = static_cast<std::size_t>(op);
  return index < std::size(NAMES) ? NAMES[index] : "unknown";
}

const UsbDeviceHandle& ForwardingTransport::inner_handle(
    const UsbDeviceHandle& handle) const noexcept {
  if (handle.transport() != this) return empty_;
  const auto it = handles_.find(handle.id());
  return it == handles_.end() ? empty_ : it->second;
}

SeamCall ForwardingTransport::call_on(SeamOp op, const UsbDeviceHandle& handle,
                                      std::uint8_t number) const noexcept {
  SeamCall call;
  call.op = op;
  call.handle = handle.transport() == this ? handle.id() : 0;
  call.number = number;
  return call;
}

Result<std::vector<drivers::UsbDeviceInfo>, UsbError> ForwardingTransport::enumerate(
    std::uint16_t vendor, std::optional<std::uint16_t> product) {
  SeamCall call;
  call.op = SeamOp::ENUMERATE;
  call.vendor = vendor;
  call.product = product;
  on_call(call);
  auto list_result = inner_.enumerate(vendor, product);
  if (list_result) call.bytes = list_result->size();
  return finish(call, std::move(list_result));
}

Result<UsbDeviceHandle, UsbError> ForwardingTransport::open(const drivers::UsbDeviceInfo& device) {
  SeamCall call;
  call.op = SeamOp::OPEN;
  call.device = &device;
  on_call(call);
  auto opened = inner_.open(device);
  call.done = true;
  if (!opened) {
    call.error = opened.error();
    on_call(call);
    return orthoflow::err(opened.error());
  }
  const std::uint32_t id = next_id_++;
  handles_.emplace(id, std::move(opened).value());
  call.handle = id;
  on_call(call);
  return make_handle(id);
}

void ForwardingTransport::close_device(std::uint32_t id) noexcept {
  const auto it = handles_.find(id);
  if (it == handles_.end()) return;
  SeamCall call;
  call.op = SeamOp::CLOSE;
  call.handle = id;
  on_call(call);
  inner_.close(it->second);
  handles_.erase(it);
  call.done = true;
  on_call(call);
}

Result<void, UsbError> ForwardingTransport::claim_interface(const UsbDeviceHandle& handle,
                                                            std::uint8_t interface_number) {
  SeamCall call = call_on(SeamOp::CLAIM_INTERFACE, handle, interface_number);
  on_call(call);
  return finish(call, inner_.claim_interface(inner_handle(handle), interface_number));
}

Result<void, UsbError> ForwardingTransport::release_interface(const UsbDeviceHandle& handle,
                                                              std::uint8_t interface_number) {
  SeamCall call = call_on(SeamOp::RELEASE_INTERFACE, handle, interface_number);
  on_call(call);
  return finish(call, inner_.release_interface(inner_handle(handle), interface_number));
}

Result<void, UsbError> ForwardingTransport::set_alt_setting(const UsbDeviceHandle& handle,
                                                            std::uint8_t interface_number,
                                                            std::uint8_t alt_setting) {
  SeamCall call = call_on(SeamOp::SET_ALT_SETTING, handle, interface_number);
  call.alt_setting = alt_setting;
  on_call(call);
  return finish(call, inner_.set_alt_setting(inner_handle(handle), interface_number, alt_setting));
}

Result<bool, UsbError> ForwardingTransport::kernel_driver_active(const UsbDeviceHandle& handle,
                                                                 std::uint8_t interface_number) {
  SeamCall call = call_on(SeamOp::KERNEL_DRIVER_ACTIVE, handle, interface_number);
  on_call(call);
  return finish(call, inner_.kernel_driver_active(inner_handle(handle), interface_number));
}

Result<void, UsbError> ForwardingTransport::detach_kernel_driver(const UsbDeviceHandle& handle,
                                                                 std::uint8_t interface_number) {
  SeamCall call = call_on(SeamOp::DETACH_KERNEL_DRIVER, handle, interface_number);
  on_call(call);
  return finish(call, inner_.detach_kernel_driver(inner_handle(handle), interface_number));
}

Result<void, UsbError> ForwardingTransport::attach_kernel_driver(const UsbDeviceHandle& handle,
                                                                 std::uint8_t interface_number) {
  SeamCall call = call_on(SeamOp::ATTACH_KERNEL_DRIVER, handle, interface_number);
  on_call(call);
  return finish(call, inner_.attach_kernel_driver(inner_handle(handle), interface_number));
}

Result<void, UsbError> ForwardingTransport::reset_device(const UsbDeviceHandle& handle) {
  SeamCall call = call_on(SeamOp::RESET_DEVICE, handle);
  on_call(call);
  return finish(call, inner_.reset_device(inner_handle(handle)));
}

Result<void, UsbError> ForwardingTransport::clear_halt(const UsbDeviceHandle& handle,
                                                       std::uint8_t endpoint) {
  SeamCall call = call_on(SeamOp::CLEAR_HALT, handle, endpoint);
  on_call(call);
  return finish(call, inner_.clear_halt(inner_handle(handle), endpoint));
}

}  // namespace orthoflow::simulation
