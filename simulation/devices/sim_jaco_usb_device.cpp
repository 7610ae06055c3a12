// SimJacoUsbDevice: the JACO's descriptors, interrupt pipes and unplug fault on the simulated host.
#include "simulation/devices/sim_jaco_usb_device.hpp"

#include <algorithm>
#include <utility>

#include "core/assert.hpp"

namespace orthoflow::simulation {

namespace jaco = drivers::jaco;

namespace {

constexpr std::uint16_t JACO_BCD_DEVICE = 0x0100;  // [I] JACO.md names none

}  // namespace

SimJacoUsbDevice::SimJacoUsbDevice(SimJacoConfig config, std::int64_t start_ns)
    : arm_(std::make_unique<SimJacoArm>(std::move(config), start_ns)) {}

drivers::UsbDeviceInfo SimJacoUsbDevice::info(std::size_t) const noexcept {
  const SimJacoConfig& c = arm_->config();
  drivers::UsbDeviceInfo info;
  info.bus = c.bus;
  info.address = address_;
  info.port_path[0] = c.port;
  info.port_depth = 1;
  info.vendor = jaco::VENDOR_KINOVA;
  info.product = jaco::PID_JACO;
  info.bcd_device = JACO_BCD_DEVICE;
  info.interface_count = 1;
  info.serial.assign(c.usb_serial);  // empty by default [I]
  return info;
}

std::uint8_t SimJacoUsbDevice::alt_settings(std::size_t, std::uint8_t interface) const noexcept {
  return interface == jaco::INTERFACE ? 1 : 0;
}

std::optional<SimEndpoint> SimJacoUsbDevice::endpoint(std::size_t,
                                                      std::uint8_t address) const noexcept {
  if (address != jaco::EP_OUT && address != jaco::EP_IN) return std::nullopt;
  SimEndpoint ep{SimEndpointType::INTERRUPT, jaco::PACKET_BYTES, jaco::INTERFACE};
  ep.whole_packets = true;  // the firmware only takes whole packets
  return ep;
}

void SimJacoUsbDevice::interrupt_out(std::size_t, std::uint8_t, std::span<const std::byte> packet,
                                     std::int64_t now_ns) noexcept {
  OF_ENFORCE(packet.size() == jaco::PACKET_BYTES, "SimJacoUsbDevice: an OUT is one packet");
  jaco::Packet copy{};
  std::copy(packet.begin(), packet.end(), copy.begin());
  arm_->receive(copy, now_ns);
}

bool SimJacoUsbDevice::interrupt_pending(std::size_t, std::uint8_t endpoint) const noexcept {
  return endpoint == jaco::EP_IN && arm_->has_reply();
}

std::size_t SimJacoUsbDevice::interrupt_in(std::size_t, std::uint8_t,
                                           std::span<std::byte> packet) noexcept {
  const jaco::Packet reply = arm_->take_reply();
  OF_ENFORCE(packet.size() >= reply.size(), "SimJacoUsbDevice: the IN buffer holds a packet");
  std::copy(reply.begin(), reply.end(), packet.begin());
  return reply.size();
}

void SimJacoUsbDevice::reset(std::size_t, std::int64_t) noexcept { arm_->reset_replies(); }

void SimJacoUsbDevice::replugged(std::int64_t) noexcept { arm_->reset_replies(); }

SimDeviceEvent SimJacoUsbDevice::next_event(bool) const noexcept {
  const std::optional<std::int64_t>& at = arm_->config().faults.unplug_at_ns;
  return {!unplug_done_ && at ? *at : SIM_USB_NEVER, false};
}

SimPlugAction SimJacoUsbDevice::take_event(std::int64_t, bool) noexcept {
  unplug_done_ = true;
  return SimPlugAction::UNPLUG;
}

}  // namespace orthoflow::simulation
