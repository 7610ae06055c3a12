// SimUsbTransport: the simulated host with Kinect-numbered accessors, and the one simulated camera
// of the CLI and the graph node.
#include "simulation/devices/sim_usb_transport.hpp"

#include <utility>

#include "core/assert.hpp"
#include "simulation/devices/sim_kinect_usb_device.hpp"

namespace orthoflow::simulation {

namespace {

SimUsbHostConfig to_host_config(const SimUsbTransportConfig& c) noexcept {
  SimUsbHostConfig host;
  host.control_latency = c.control_latency;
  host.infinite_wait = c.infinite_wait;
  host.first_address = c.first_address;
  return host;
}

}  // namespace

SimUsbTransport::SimUsbTransport(SimUsbTransportConfig config)
    : SimUsbHost(to_host_config(config)) {}

SimUsbTransport::SimUsbTransport(drivers::ManualClock& clock, SimUsbTransportConfig config)
    : SimUsbHost(clock, to_host_config(config)) {}

const SimUsbTransport::Kinect& SimUsbTransport::at(std::size_t index, const char* operation) const {
  OF_ENFORCE(index < kinects_.size(), operation);
  return kinects_[index];
}

std::size_t SimUsbTransport::add_kinect(SimKinectConfig config) {
  auto device = std::make_unique<SimKinectUsbDevice>(std::move(config));
  SimKinectDevice* model = &device->model();
  kinects_.push_back({add_device(std::move(device)), model});
  return kinects_.size() - 1;
}

SimKinectDevice& SimUsbTransport::kinect(std::size_t index) {
  return *at(index, "SimUsbTransport::kinect: no such Kinect").model;
}

bool SimUsbTransport::present(std::size_t index) const {
  return device_present(at(index, "SimUsbTransport::present: no such Kinect").device);
}

void SimUsbTransport::unplug(std::size_t index) {
  unplug_device(at(index, "SimUsbTransport::unplug: no such Kinect").device);
}

void SimUsbTransport::replug(std::size_t index) {
  replug_device(at(index, "SimUsbTransport::replug: no such Kinect").device);
}

std::unique_ptr<SimUsbTransport> make_sim_kinect_host(const SimKinectHostOptions& options) {
  OF_ENFORCE(options.drop_rate >= 0.0 && options.drop_rate <= 1.0,
             "make_sim_kinect_host: the drop rate lies in [0, 1]");
  auto host = std::make_unique<SimUsbTransport>();
  SimKinectConfig config;
  config.model = options.model;
  config.scene_seed = options.scene_seed;
  config.faults.packets.drop_rate = options.drop_rate;
  if (!options.serial.empty()) config.serial = options.serial;
  host->add_kinect(std::move(config));
  return host;
}

}  // namespace orthoflow::simulation
