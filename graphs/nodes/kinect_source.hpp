#pragma once
/// @file
/// @brief `kinect_source`: the tabletop graph's frames from a Kinect v1 camera through the
/// orthoflow driver (drivers/kinect/kinect_device.hpp): `device: usb` (libusb, real hardware) or
/// `device: sim` (the simulated camera of simulation/devices/sim_usb_transport.hpp, paced to the
/// wall clock). Depth becomes an organized 640x480 cloud with the device's own calibration.
#include "engine/registry.hpp"

namespace orthoflow::graphs {

/// @brief Registers kinect_source.
void add_kinect_source(engine::NodeRegistry& registry);

}  // namespace orthoflow::graphs
