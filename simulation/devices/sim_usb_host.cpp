// SimUsbHost: devices on the bus (plug, unplug, replug, addresses), enumeration, handles and
// closing. Interfaces: sim_usb_host_interfaces.cpp; transfers: sim_usb_host_transfers.cpp; iso
// streams: sim_usb_host_iso.cpp; events and simulated time: sim_usb_host_time.cpp.
#include "simulation/devices/sim_usb_host.hpp"

#include <algorithm>
#include <utility>

#include "core/assert.hpp"
#include "simulation/devices/sim_usb_host_state.hpp"

namespace orthoflow::simulation {

using drivers::UsbError;

namespace {

constexpr unsigned LAST_ADDRESS = 127;  // USB addresses are 1..127

Unexpected<UsbError> refused(UsbError::Code code, const char* operation) {
  return orthoflow::err(UsbError{code, 0, operation});
}

}  // namespace

SimUsbHost::SimUsbHost(SimUsbHostConfig config)
    : config_(config),
      owned_clock_(std::make_unique<drivers::ManualClock>(0)),
      clock_(owned_clock_.get()) {
  next_address_.fill(config_.first_address);
}

SimUsbHost::SimUsbHost(drivers::ManualClock& clock, SimUsbHostConfig config)
    : config_(config), clock_(&clock) {
  next_address_.fill(config_.first_address);
}

SimUsbHost::~SimUsbHost() = default;

void SimUsbHost::enforce_not_in_callback() const noexcept {
  OF_ENFORCE(!in_callback_, "SimUsbHost: an iso callback must not call the transport");
}

void SimUsbHost::assign_addresses(Slot& slot) {
  // The device's hub addresses first, then one per function (absent ones too), never reused.
  SimUsbDevice& device = *slot.device;
  std::uint8_t& next = next_address_[device.bus()];
  const std::size_t hubs = device.hub_addresses();
  const std::size_t count = hubs + device.function_count();
  OF_ENFORCE(next + count - 1 <= LAST_ADDRESS,
             "SimUsbHost: the simulated bus ran out of addresses");
  for (std::size_t f = 0; f < device.function_count(); ++f)
    device.set_address(f, static_cast<std::uint8_t>(next + hubs + f));
  next = static_cast<std::uint8_t>(next + count);
}

void SimUsbHost::sync_generations(Slot& slot) noexcept {
  for (std::size_t f = 0; f < slot.functions.size(); ++f)
    slot.functions[f].generation = slot.device->generation(f);
}

void SimUsbHost::refresh_functions(Slot& slot) {
  if (!slot.present) return;
  for (std::size_t f = 0; f < slot.functions.size(); ++f) {
    Function& fn = slot.functions[f];
    SimUsbDevice& device = *slot.device;
    if (device.generation(f) == fn.generation || !device.present(f, clock_->now_ns())) continue;
    // Back from a re-enumeration: a new address, and the old claims went with the old device.
    std::uint8_t& next = next_address_[device.bus()];
    OF_ENFORCE(next <= LAST_ADDRESS, "SimUsbHost: the simulated bus ran out of addresses");
    device.set_address(f, next);
    next = static_cast<std::uint8_t>(next + 1);
    fn.generation = device.generation(f);
    fn.claimed_by = {};
  }
}

std::size_t SimUsbHost::add_device(std::unique_ptr<SimUsbDevice> device) {
  enforce_not_in_callback();
  OF_ENFORCE(device != nullptr, "SimUsbHost::add_device: no device");
  auto slot = std::make_unique<Slot>();
  slot->device = std::move(device);
  slot->functions.resize(slot->device->function_count());
  for (std::size_t f = 0; f < slot->functions.size(); ++f) {
    for (std::uint8_t i = 0; i < SIM_USB_MAX_INTERFACES; ++i)
      slot->functions[f].kernel_bound[i] = slot->device->kernel_driver(f, i);
  }
  sync_generations(*slot);
  assign_addresses(*slot);
  slots_.push_back(std::move(slot));
  return slots_.size() - 1;
}

SimUsbDevice& SimUsbHost::device(std::size_t index) {
  OF_ENFORCE(index < slots_.size(), "SimUsbHost::device: no such device");
  return *slots_[index]->device;
}

bool SimUsbHost::device_present(std::size_t index) const {
  OF_ENFORCE(index < slots_.size(), "SimUsbHost::device_present: no such device");
  return slots_[index]->present;
}

void SimUsbHost::unplug_device(std::size_t index) {
  enforce_not_in_callback();
  OF_ENFORCE(index < slots_.size(), "SimUsbHost::unplug_device: no such device");
  run_until(clock_->now_ns());
  Slot& slot = *slots_[index];
  if (!slot.present) return;
  fail_streams(index, drivers::UsbPacketStatus::NO_DEVICE);
  slot.present = false;
  for (Function& fn : slot.functions) fn.claimed_by = {};
  slot.device->unplugged(clock_->now_ns());
  sync_generations(slot);
}

void SimUsbHost::replug_device(std::size_t index) {
  enforce_not_in_callback();
  OF_ENFORCE(index < slots_.size(), "SimUsbHost::replug_device: no such device");
  Slot& slot = *slots_[index];
  if (slot.present) return;
  slot.present = true;
  ++slot.epoch;
  for (std::size_t f = 0; f < slot.functions.size(); ++f) {
    Function& fn = slot.functions[f];
    fn.claimed_by = {};
    for (std::uint8_t i = 0; i < SIM_USB_MAX_INTERFACES; ++i)
      fn.kernel_bound[i] = slot.device->kernel_driver(f, i);  // the OS binds it again
  }
  slot.device->replugged(clock_->now_ns());
  sync_generations(slot);
  assign_addresses(slot);
}

Result<std::vector<drivers::UsbDeviceInfo>, UsbError> SimUsbHost::enumerate(
    std::uint16_t vendor, std::optional<std::uint16_t> product) {
  enforce_not_in_callback();
  run_until(clock_->now_ns());  // an unplug that is due shows here
  std::vector<drivers::UsbDeviceInfo> found;
  for (const auto& slot : slots_) {
    refresh_functions(*slot);
    if (!slot->present) continue;
    for (std::size_t f = 0; f < slot->functions.size(); ++f) {
      if (!slot->device->present(f, clock_->now_ns())) continue;
      const drivers::UsbDeviceInfo info = slot->device->info(f);
      if (info.vendor == vendor && (!product || info.product == *product)) found.push_back(info);
    }
  }
  return found;
}

Result<drivers::UsbDeviceHandle, UsbError> SimUsbHost::open(const drivers::UsbDeviceInfo& device) {
  enforce_not_in_callback();
  run_until(clock_->now_ns());
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    Slot& slot = *slots_[k];
    refresh_functions(slot);
    if (!slot.present) continue;
    for (std::size_t f = 0; f < slot.functions.size(); ++f) {
      if (!slot.device->present(f, clock_->now_ns())) continue;
      const drivers::UsbDeviceInfo info = slot.device->info(f);
      if (info.bus != device.bus || info.address != device.address ||
          info.vendor != device.vendor || info.product != device.product)
        continue;
      auto h = std::make_unique<Handle>();
      h->id = next_handle_id_++;
      h->slot = k;
      h->function = f;
      h->epoch = slot.epoch;
      h->generation = slot.device->generation(f);
      handles_.push_back(std::move(h));
      return make_handle(handles_.back()->id);
    }
  }
  return refused(UsbError::Code::NO_DEVICE, "open");
}

bool SimUsbHost::alive(const Handle& h) const noexcept {
  const Slot& slot = *slots_[h.slot];
  return slot.present && slot.epoch == h.epoch;
}

Result<SimUsbHost::Handle*, UsbError> SimUsbHost::lookup(const drivers::UsbDeviceHandle& handle,
                                                         const char* operation,
                                                         bool need_device) const {
  enforce_not_in_callback();
  if (handle.transport() != this) return refused(UsbError::Code::NOT_OPEN, operation);
  const auto it = std::find_if(handles_.begin(), handles_.end(),
                               [&](const auto& h) { return h->id == handle.id(); });
  if (it == handles_.end()) return refused(UsbError::Code::NOT_OPEN, operation);
  Handle* h = it->get();
  if (!need_device) return h;
  const SimUsbDevice& device = *slots_[h->slot]->device;
  if (!alive(*h) || h->generation != device.generation(h->function) ||
      !device.present(h->function, clock_->now_ns()))
    return refused(UsbError::Code::NO_DEVICE, operation);
  return h;
}

Result<SimUsbHost::Handle*, UsbError> SimUsbHost::interface_of(
    const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number,
    const char* operation) const {
  auto h_result = lookup(handle, operation, true);
  if (!h_result) return h_result;
  const Handle& h = **h_result;
  if (interface_number >= SIM_USB_MAX_INTERFACES ||
      slots_[h.slot]->device->alt_settings(h.function, interface_number) == 0)
    return refused(UsbError::Code::NOT_FOUND, operation);
  return h_result;
}

std::optional<SimEndpoint> SimUsbHost::endpoint_of(const Handle& h, std::uint8_t endpoint,
                                                   SimEndpointType type) const noexcept {
  // A transfer needs a simulated endpoint of its type on an interface this handle claims.
  const std::optional<SimEndpoint> ep = slots_[h.slot]->device->endpoint(h.function, endpoint);
  if (!ep || !ep->simulated || ep->type != type || !h.claims(ep->interface)) return std::nullopt;
  return ep;
}

bool SimUsbHost::streaming(const Handle& h) const noexcept {
  return std::any_of(streams_.begin(), streams_.end(),
                     [&](const auto& s) { return s->handle == h.id; });
}

SimUsbHost::Stream* SimUsbHost::find_stream(std::uint32_t handle_id,
                                            std::uint8_t endpoint) const noexcept {
  for (const auto& s : streams_) {
    if (s->handle == handle_id && s->endpoint == endpoint) return s.get();
  }
  return nullptr;
}

void SimUsbHost::close_device(std::uint32_t id) noexcept {
  enforce_not_in_callback();
  const auto it =
      std::find_if(handles_.begin(), handles_.end(), [&](const auto& h) { return h->id == id; });
  if (it == handles_.end()) return;
  const Handle& h = **it;
  std::erase_if(streams_, [&](const auto& s) { return s->handle == id; });
  Slot& slot = *slots_[h.slot];
  if (h.epoch == slot.epoch) {
    Function& fn = slot.functions[h.function];
    for (std::uint8_t i = 0; i < SIM_USB_MAX_INTERFACES; ++i) {
      if (fn.claimed_by[i] == id) fn.claimed_by[i] = 0;
      if (((h.detached >> i) & 1U) != 0 && slot.present) fn.kernel_bound[i] = true;  // re-attach
    }
  }
  handles_.erase(it);
}

}  // namespace orthoflow::simulation
