// SimUsbHost: interface claims, alternate settings, kernel-driver binding, port reset and halts.
#include <algorithm>

#include "core/assert.hpp"
#include "simulation/devices/sim_usb_host.hpp"
#include "simulation/devices/sim_usb_host_state.hpp"

namespace orthoflow::simulation {

using drivers::UsbError;

namespace {

Unexpected<UsbError> refused(UsbError::Code code, const char* operation) {
  return orthoflow::err(UsbError{code, 0, operation});
}

std::uint8_t bit(std::uint8_t interface_number) noexcept {
  return static_cast<std::uint8_t>(1U << interface_number);
}

}  // namespace

void SimUsbHost::step_devices() noexcept {
  // Devices keep time even between events (a hand-moved clock): step them to now, quietly.
  for (const auto& slot : slots_) slot->device->advance(clock_->now_ns());
}

Result<void, UsbError> SimUsbHost::claim_interface(const drivers::UsbDeviceHandle& handle,
                                                   std::uint8_t interface_number) {
  step_devices();
  auto h_result = interface_of(handle, interface_number, "claim_interface");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  Function& fn = slots_[h.slot]->functions[h.function];
  std::uint32_t& owner = fn.claimed_by[interface_number];
  if (h.claims(interface_number) || owner != 0 || fn.kernel_bound[interface_number])
    return refused(UsbError::Code::BUSY, "claim_interface");
  owner = h.id;
  h.claimed = static_cast<std::uint8_t>(h.claimed | bit(interface_number));
  return {};
}

Result<void, UsbError> SimUsbHost::release_interface(const drivers::UsbDeviceHandle& handle,
                                                     std::uint8_t interface_number) {
  step_devices();
  auto h_result = interface_of(handle, interface_number, "release_interface");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  if (!h.claims(interface_number)) return refused(UsbError::Code::NOT_FOUND, "release_interface");
  if (streaming(h)) return refused(UsbError::Code::BUSY, "release_interface");
  h.claimed = static_cast<std::uint8_t>(h.claimed & ~bit(interface_number));
  slots_[h.slot]->functions[h.function].claimed_by[interface_number] = 0;
  return {};
}

Result<void, UsbError> SimUsbHost::set_alt_setting(const drivers::UsbDeviceHandle& handle,
                                                   std::uint8_t interface_number,
                                                   std::uint8_t alt_setting) {
  auto h_result = interface_of(handle, interface_number, "set_alt_setting");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  const std::uint8_t alts = slots_[h.slot]->device->alt_settings(h.function, interface_number);
  if (!h.claims(interface_number) || alt_setting >= alts)
    return refused(UsbError::Code::NOT_FOUND, "set_alt_setting");
  if (streaming(h)) return refused(UsbError::Code::BUSY, "set_alt_setting");
  h.alt[interface_number] = alt_setting;
  return {};
}

Result<bool, UsbError> SimUsbHost::kernel_driver_active(const drivers::UsbDeviceHandle& handle,
                                                        std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "kernel_driver_active");
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  return slots_[h.slot]->functions[h.function].kernel_bound[interface_number];
}

Result<void, UsbError> SimUsbHost::detach_kernel_driver(const drivers::UsbDeviceHandle& handle,
                                                        std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "detach_kernel_driver");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  bool& bound = slots_[h.slot]->functions[h.function].kernel_bound[interface_number];
  if (!bound) return refused(UsbError::Code::NOT_FOUND, "detach_kernel_driver");
  bound = false;
  h.detached = static_cast<std::uint8_t>(h.detached | bit(interface_number));
  return {};
}

Result<void, UsbError> SimUsbHost::attach_kernel_driver(const drivers::UsbDeviceHandle& handle,
                                                        std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "attach_kernel_driver");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  Function& fn = slots_[h.slot]->functions[h.function];
  if (!slots_[h.slot]->device->kernel_driver(h.function, interface_number))
    return refused(UsbError::Code::NOT_FOUND, "attach_kernel_driver");
  if (fn.kernel_bound[interface_number] || fn.claimed_by[interface_number] != 0)
    return refused(UsbError::Code::BUSY, "attach_kernel_driver");
  fn.kernel_bound[interface_number] = true;
  h.detached = static_cast<std::uint8_t>(h.detached & ~bit(interface_number));
  return {};
}

Result<void, UsbError> SimUsbHost::reset_device(const drivers::UsbDeviceHandle& handle) {
  step_devices();
  auto h_result = lookup(handle, "reset_device", true);
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  if (streaming(h)) return refused(UsbError::Code::BUSY, "reset_device");
  // Same descriptors after the reset, so the handle stays valid (libusb's rule).
  slots_[h.slot]->device->reset(h.function, clock_->now_ns());
  return {};
}

Result<void, UsbError> SimUsbHost::clear_halt(const drivers::UsbDeviceHandle& handle,
                                              std::uint8_t endpoint) {
  auto h_result = lookup(handle, "clear_halt", true);
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  const std::optional<SimEndpoint> ep = slots_[h.slot]->device->endpoint(h.function, endpoint);
  if (endpoint != 0 && (!ep || !ep->simulated))
    return refused(UsbError::Code::NOT_FOUND, "clear_halt");
  if (find_stream(h.id, endpoint) != nullptr) return refused(UsbError::Code::BUSY, "clear_halt");
  return {};
}

Result<std::size_t, UsbError> SimUsbHost::max_iso_packet_size(
    const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint) {
  auto h_result = lookup(handle, "max_iso_packet_size", true);
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  const std::optional<SimEndpoint> ep = slots_[h.slot]->device->endpoint(h.function, endpoint);
  if (!ep || ep->type != SimEndpointType::ISO)
    return refused(UsbError::Code::NOT_FOUND, "max_iso_packet_size");
  return ep->max_packet;
}

}  // namespace orthoflow::simulation
