// SimJacoTransport: devices, handles, interface 0, the interrupt pipes and simulated time.
#include "simulation/sim_jaco_transport.hpp"

#include <algorithm>
#include <climits>
#include <utility>

#include "core/assert.hpp"

namespace orthoflow::simulation {

using drivers::UsbError;
namespace jaco = drivers::jaco;

namespace {

Unexpected<UsbError> refused(UsbError::Code code, const char* operation) {
  return orthoflow::err(UsbError{code, 0, operation});
}

constexpr std::uint16_t JACO_BCD_DEVICE = 0x0100;  // [I] JACO.md names none

}  // namespace

SimJacoTransport::SimJacoTransport(SimJacoTransportConfig config)
    : config_(config),
      owned_clock_(std::make_unique<drivers::ManualClock>(0)),
      clock_(owned_clock_.get()) {
  next_address_.fill(config_.first_address);
}

SimJacoTransport::SimJacoTransport(drivers::ManualClock& clock, SimJacoTransportConfig config)
    : config_(config), clock_(&clock) {
  next_address_.fill(config_.first_address);
}

SimJacoTransport::~SimJacoTransport() = default;

void SimJacoTransport::assign_address(Slot& slot) {
  std::uint8_t& next = next_address_[slot.arm->config().bus];
  OF_ENFORCE(next <= 127, "SimJacoTransport: the simulated bus ran out of addresses");
  slot.address = next;
  next = static_cast<std::uint8_t>(next + 1);
}

std::size_t SimJacoTransport::add_arm(SimJacoConfig config) {
  run_until(clock_->now_ns());
  auto slot = std::make_unique<Slot>();
  slot->arm = std::make_unique<SimJacoArm>(std::move(config), clock_->now_ns());
  assign_address(*slot);
  slots_.push_back(std::move(slot));
  return slots_.size() - 1;
}

SimJacoArm& SimJacoTransport::arm(std::size_t index) {
  OF_ENFORCE(index < slots_.size(), "SimJacoTransport::arm: no such arm");
  return *slots_[index]->arm;
}

bool SimJacoTransport::present(std::size_t index) const {
  OF_ENFORCE(index < slots_.size(), "SimJacoTransport::present: no such arm");
  return slots_[index]->present;
}

void SimJacoTransport::unplug(std::size_t index) {
  OF_ENFORCE(index < slots_.size(), "SimJacoTransport::unplug: no such arm");
  run_until(clock_->now_ns());
  slots_[index]->present = false;
}

void SimJacoTransport::replug(std::size_t index) {
  OF_ENFORCE(index < slots_.size(), "SimJacoTransport::replug: no such arm");
  run_until(clock_->now_ns());
  Slot& slot = *slots_[index];
  if (slot.present) return;
  slot.present = true;
  ++slot.epoch;
  slot.claimed_by = 0;
  assign_address(slot);
  slot.arm->reset_replies();
}

void SimJacoTransport::apply_unplug_faults(std::int64_t t_ns) {
  for (const auto& slot : slots_) {
    const std::optional<std::int64_t>& at = slot->arm->config().faults.unplug_at_ns;
    if (!slot->unplug_fault_done && at && *at <= t_ns) {
      slot->unplug_fault_done = true;
      slot->present = false;
    }
  }
}

void SimJacoTransport::run_until(std::int64_t t_ns) {
  if (t_ns > clock_->now_ns()) clock_->set_ns(t_ns);
  const std::int64_t now = clock_->now_ns();
  apply_unplug_faults(now);
  for (const auto& slot : slots_) slot->arm->step(now);
}

void SimJacoTransport::run_for(std::chrono::nanoseconds duration) {
  OF_ENFORCE(duration.count() >= 0, "SimJacoTransport::run_for: time never goes back");
  run_until(clock_->now_ns() + duration.count());
}

bool SimJacoTransport::alive(const Handle& h) const noexcept {
  const Slot& slot = *slots_[h.arm];
  return slot.present && slot.epoch == h.epoch;
}

bool SimJacoTransport::run_while_alive(const Handle& h, std::int64_t t_ns) {
  // Stops at the unplug if the cable is pulled on the way: the transfer ends there.
  const Slot& slot = *slots_[h.arm];
  const std::optional<std::int64_t>& at = slot.arm->config().faults.unplug_at_ns;
  if (!slot.unplug_fault_done && at && *at <= t_ns) {
    run_until(*at);
    return false;
  }
  run_until(t_ns);
  return alive(h);
}

drivers::UsbDeviceInfo SimJacoTransport::info(const Slot& slot) const noexcept {
  drivers::UsbDeviceInfo info;
  info.bus = slot.arm->config().bus;
  info.address = slot.address;
  info.port_path[0] = slot.arm->config().port;
  info.port_depth = 1;
  info.vendor = jaco::VENDOR_KINOVA;
  info.product = jaco::PID_JACO;
  info.bcd_device = JACO_BCD_DEVICE;
  info.interface_count = 1;
  info.serial.assign(slot.arm->config().usb_serial);  // empty by default [I]
  return info;
}

Result<std::vector<drivers::UsbDeviceInfo>, UsbError> SimJacoTransport::enumerate(
    std::uint16_t vendor, std::optional<std::uint16_t> product) {
  run_until(clock_->now_ns());
  std::vector<drivers::UsbDeviceInfo> found;
  if (vendor != jaco::VENDOR_KINOVA || (product && *product != jaco::PID_JACO)) return found;
  for (const auto& slot : slots_) {
    if (slot->present) found.push_back(info(*slot));
  }
  return found;
}

Result<drivers::UsbDeviceHandle, UsbError> SimJacoTransport::open(
    const drivers::UsbDeviceInfo& device) {
  run_until(clock_->now_ns());
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    const Slot& slot = *slots_[k];
    const drivers::UsbDeviceInfo i = info(slot);
    if (!slot.present || i.bus != device.bus || i.address != device.address ||
        i.vendor != device.vendor || i.product != device.product)
      continue;
    handles_.push_back(std::make_unique<Handle>(Handle{next_handle_id_++, k, slot.epoch, false}));
    return make_handle(handles_.back()->id);
  }
  return refused(UsbError::Code::NO_DEVICE, "open");
}

Result<SimJacoTransport::Handle*, UsbError> SimJacoTransport::lookup(
    const drivers::UsbDeviceHandle& handle, const char* operation, bool need_device) const {
  if (handle.transport() != this) return refused(UsbError::Code::NOT_OPEN, operation);
  const auto it = std::find_if(handles_.begin(), handles_.end(),
                               [&](const auto& h) { return h->id == handle.id(); });
  if (it == handles_.end()) return refused(UsbError::Code::NOT_OPEN, operation);
  Handle* h = it->get();
  if (need_device && !alive(*h)) return refused(UsbError::Code::NO_DEVICE, operation);
  return h;
}

Result<SimJacoTransport::Handle*, UsbError> SimJacoTransport::interface_of(
    const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number,
    const char* operation) const {
  auto h_result = lookup(handle, operation, true);
  if (!h_result) return h_result;
  if (interface_number != jaco::INTERFACE) return refused(UsbError::Code::NOT_FOUND, operation);
  return h_result;
}

Result<void, UsbError> SimJacoTransport::claim_interface(const drivers::UsbDeviceHandle& handle,
                                                         std::uint8_t interface_number) {
  run_until(clock_->now_ns());
  auto h_result = interface_of(handle, interface_number, "claim_interface");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  Slot& slot = *slots_[h.arm];
  if (h.claimed || slot.claimed_by != 0) return refused(UsbError::Code::BUSY, "claim_interface");
  slot.claimed_by = h.id;
  h.claimed = true;
  return {};
}

Result<void, UsbError> SimJacoTransport::release_interface(const drivers::UsbDeviceHandle& handle,
                                                           std::uint8_t interface_number) {
  run_until(clock_->now_ns());
  auto h_result = interface_of(handle, interface_number, "release_interface");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  if (!h.claimed) return refused(UsbError::Code::NOT_FOUND, "release_interface");
  h.claimed = false;
  slots_[h.arm]->claimed_by = 0;
  return {};
}

Result<void, UsbError> SimJacoTransport::set_alt_setting(const drivers::UsbDeviceHandle& handle,
                                                         std::uint8_t interface_number,
                                                         std::uint8_t alt_setting) {
  auto h_result = interface_of(handle, interface_number, "set_alt_setting");
  if (!h_result) return orthoflow::err(h_result.error());
  if (!(*h_result)->claimed || alt_setting != 0)
    return refused(UsbError::Code::NOT_FOUND, "set_alt_setting");
  return {};
}

Result<bool, UsbError> SimJacoTransport::kernel_driver_active(
    const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "kernel_driver_active");
  if (!h_result) return orthoflow::err(h_result.error());
  return false;
}

Result<void, UsbError> SimJacoTransport::detach_kernel_driver(
    const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "detach_kernel_driver");
  if (!h_result) return orthoflow::err(h_result.error());
  return refused(UsbError::Code::NOT_FOUND, "detach_kernel_driver");
}

Result<void, UsbError> SimJacoTransport::attach_kernel_driver(
    const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "attach_kernel_driver");
  if (!h_result) return orthoflow::err(h_result.error());
  return refused(UsbError::Code::NOT_FOUND, "attach_kernel_driver");
}

Result<void, UsbError> SimJacoTransport::reset_device(const drivers::UsbDeviceHandle& handle) {
  run_until(clock_->now_ns());
  auto h_result = lookup(handle, "reset_device", true);
  if (!h_result) return orthoflow::err(h_result.error());
  slots_[(*h_result)->arm]->arm->reset_replies();
  return {};
}

Result<void, UsbError> SimJacoTransport::clear_halt(const drivers::UsbDeviceHandle& handle,
                                                    std::uint8_t endpoint) {
  auto h_result = lookup(handle, "clear_halt", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (endpoint != 0 && endpoint != jaco::EP_OUT && endpoint != jaco::EP_IN)
    return refused(UsbError::Code::NOT_FOUND, "clear_halt");
  return {};
}

Result<std::size_t, UsbError> SimJacoTransport::control(const drivers::UsbDeviceHandle& handle,
                                                        const drivers::UsbControlSetup&,
                                                        std::span<std::byte> data,
                                                        drivers::UsbTimeout) {
  auto h_result = lookup(handle, "control", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > 65535) return refused(UsbError::Code::INVALID_PARAM, "control");
  return refused(UsbError::Code::NOT_SUPPORTED, "control");
}

Result<std::size_t, UsbError> SimJacoTransport::bulk(const drivers::UsbDeviceHandle& handle,
                                                     std::uint8_t, std::span<std::byte> data,
                                                     drivers::UsbTimeout) {
  auto h_result = lookup(handle, "bulk", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > INT_MAX) return refused(UsbError::Code::INVALID_PARAM, "bulk");
  return refused(UsbError::Code::NOT_FOUND, "bulk");
}

Result<std::size_t, UsbError> SimJacoTransport::interrupt(const drivers::UsbDeviceHandle& handle,
                                                          std::uint8_t endpoint,
                                                          std::span<std::byte> data,
                                                          drivers::UsbTimeout timeout) {
  run_until(clock_->now_ns());
  auto h_result = lookup(handle, "interrupt", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > INT_MAX) return refused(UsbError::Code::INVALID_PARAM, "interrupt");
  const Handle h = **h_result;  // a copy: run_until never touches handles, but keep it simple
  if ((endpoint != jaco::EP_OUT && endpoint != jaco::EP_IN) || !h.claimed)
    return refused(UsbError::Code::NOT_FOUND, "interrupt");
  SimJacoArm& arm = *slots_[h.arm]->arm;
  const std::int64_t latency = config_.transfer_latency.count();
  if (endpoint == jaco::EP_OUT) {
    if (data.size() != jaco::PACKET_BYTES)
      return refused(UsbError::Code::INVALID_PARAM, "interrupt");
    jaco::Packet packet{};
    std::copy(data.begin(), data.end(), packet.begin());
    if (!run_while_alive(h, clock_->now_ns() + latency))
      return refused(UsbError::Code::NO_DEVICE, "interrupt");
    arm.receive(packet, clock_->now_ns());
    return jaco::PACKET_BYTES;
  }
  if (!arm.has_reply()) {
    const auto wait = timeout.count() == 0 ? config_.infinite_wait : timeout;
    const auto wait_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
    if (!run_while_alive(h, clock_->now_ns() + wait_ns))
      return refused(UsbError::Code::NO_DEVICE, "interrupt");
    return refused(UsbError::Code::TIMEOUT, "interrupt");
  }
  if (!run_while_alive(h, clock_->now_ns() + latency))
    return refused(UsbError::Code::NO_DEVICE, "interrupt");
  const jaco::Packet reply = arm.take_reply();
  if (data.size() < jaco::PACKET_BYTES)
    return orthoflow::err(UsbError{UsbError::Code::OVERFLOW, 0, "interrupt"});
  std::copy(reply.begin(), reply.end(), data.begin());
  return jaco::PACKET_BYTES;
}

Result<std::size_t, UsbError> SimJacoTransport::max_iso_packet_size(
    const drivers::UsbDeviceHandle& handle, std::uint8_t) {
  auto h_result = lookup(handle, "max_iso_packet_size", true);
  if (!h_result) return orthoflow::err(h_result.error());
  return refused(UsbError::Code::NOT_FOUND, "max_iso_packet_size");
}

Result<void, UsbError> SimJacoTransport::start_iso(const drivers::UsbDeviceHandle& handle,
                                                   std::uint8_t, const drivers::UsbIsoConfig&,
                                                   drivers::UsbIsoCallback) {
  auto h_result = lookup(handle, "start_iso", true);
  if (!h_result) return orthoflow::err(h_result.error());
  return refused(UsbError::Code::NOT_FOUND, "start_iso");
}

Result<void, UsbError> SimJacoTransport::stop_iso(const drivers::UsbDeviceHandle& handle,
                                                  std::uint8_t) {
  auto h_result = lookup(handle, "stop_iso", false);
  if (!h_result) return orthoflow::err(h_result.error());
  return refused(UsbError::Code::NOT_FOUND, "stop_iso");
}

Result<drivers::UsbIsoStats, UsbError> SimJacoTransport::iso_stats(
    const drivers::UsbDeviceHandle& handle, std::uint8_t) const {
  auto h_result = lookup(handle, "iso_stats", false);
  if (!h_result) return orthoflow::err(h_result.error());
  return refused(UsbError::Code::NOT_FOUND, "iso_stats");
}

Result<void, UsbError> SimJacoTransport::handle_events(drivers::UsbTimeout timeout) {
  if (timeout.count() < 0) return refused(UsbError::Code::INVALID_PARAM, "handle_events");
  run_until(clock_->now_ns() +
            std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count());
  return {};
}

void SimJacoTransport::close_device(std::uint32_t id) noexcept {
  const auto it =
      std::find_if(handles_.begin(), handles_.end(), [&](const auto& h) { return h->id == id; });
  if (it == handles_.end()) return;
  Slot& slot = *slots_[(*it)->arm];
  if ((*it)->epoch == slot.epoch && slot.claimed_by == id) slot.claimed_by = 0;
  handles_.erase(it);
}

}  // namespace orthoflow::simulation
