// SimJacoTransport: the simulated host with arm-numbered accessors.
#include "simulation/devices/sim_jaco_transport.hpp"

#include <memory>
#include <utility>

#include "core/assert.hpp"
#include "simulation/devices/sim_jaco_usb_device.hpp"

namespace orthoflow::simulation {

namespace {

SimUsbHostConfig to_host_config(const SimJacoTransportConfig& c) noexcept {
  SimUsbHostConfig host;
  host.interrupt_latency = c.transfer_latency;
  host.infinite_wait = c.infinite_wait;
  host.first_address = c.first_address;
  return host;
}

}  // namespace

SimJacoTransport::SimJacoTransport(SimJacoTransportConfig config)
    : SimUsbHost(to_host_config(config)) {}

SimJacoTransport::SimJacoTransport(drivers::ManualClock& clock, SimJacoTransportConfig config)
    : SimUsbHost(clock, to_host_config(config)) {}

const SimJacoTransport::Arm& SimJacoTransport::at(std::size_t index, const char* operation) const {
  OF_ENFORCE(index < arms_.size(), operation);
  return arms_[index];
}

std::size_t SimJacoTransport::add_arm(SimJacoConfig config) {
  run_for(std::chrono::nanoseconds(0));  // the arm powers on now: catch up with the clock first
  auto device = std::make_unique<SimJacoUsbDevice>(std::move(config), clock().now_ns());
  SimJacoArm* model = &device->arm();
  arms_.push_back({add_device(std::move(device)), model});
  return arms_.size() - 1;
}

SimJacoArm& SimJacoTransport::arm(std::size_t index) {
  return *at(index, "SimJacoTransport::arm: no such arm").model;
}

bool SimJacoTransport::present(std::size_t index) const {
  return device_present(at(index, "SimJacoTransport::present: no such arm").device);
}

void SimJacoTransport::unplug(std::size_t index) {
  unplug_device(at(index, "SimJacoTransport::unplug: no such arm").device);
}

void SimJacoTransport::replug(std::size_t index) {
  const std::size_t device = at(index, "SimJacoTransport::replug: no such arm").device;
  run_for(std::chrono::nanoseconds(0));  // catch up with a hand-moved clock first
  replug_device(device);
}

}  // namespace orthoflow::simulation
