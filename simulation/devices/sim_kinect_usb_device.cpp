// SimKinectUsbDevice: the Kinect's functions, descriptors and fault events on the simulated host;
// every transfer goes to SimKinectDevice.
#include "simulation/devices/sim_kinect_usb_device.hpp"

#include <algorithm>

namespace orthoflow::simulation {

namespace {

constexpr std::uint8_t AUDIO_BULK_OUT = 0x01;
constexpr std::uint8_t AUDIO_BULK_IN = 0x81;
constexpr std::uint8_t AUDIO_ISO_IN = 0x82;
constexpr std::size_t AUDIO_BULK_PACKET = 512;
constexpr std::size_t AUDIO_ISO_PACKET = 524;

KinectFunction function_of(std::size_t function) noexcept {
  return static_cast<KinectFunction>(function);
}

}  // namespace

bool SimKinectUsbDevice::present(std::size_t function, std::int64_t now_ns) const noexcept {
  return model_.present(function_of(function), now_ns);
}

drivers::UsbDeviceInfo SimKinectUsbDevice::info(std::size_t function) const noexcept {
  return model_.info(function_of(function));
}

void SimKinectUsbDevice::set_address(std::size_t function, std::uint8_t address) noexcept {
  // The model numbers its functions from the camera's address (motor + 1, audio + 2) until the
  // audio function is given one of its own.
  if (function_of(function) == KinectFunction::CAMERA) model_.set_first_address(address);
  if (function_of(function) == KinectFunction::AUDIO) model_.set_audio_address(address);
}

std::uint32_t SimKinectUsbDevice::generation(std::size_t function) const noexcept {
  return function_of(function) == KinectFunction::AUDIO ? model_.audio_generation() : 0;
}

std::uint8_t SimKinectUsbDevice::alt_settings(std::size_t function,
                                              std::uint8_t interface) const noexcept {
  if (interface != 0) return 0;
  const bool k4w_camera =
      function_of(function) == KinectFunction::CAMERA && model_.model() == KinectModel::K4W;
  return k4w_camera ? 2 : 1;
}

bool SimKinectUsbDevice::kernel_driver(std::size_t function,
                                       std::uint8_t interface) const noexcept {
  return function_of(function) == KinectFunction::CAMERA && interface == 0;  // gspca_kinect
}

std::optional<SimEndpoint> SimKinectUsbDevice::endpoint(std::size_t function,
                                                        std::uint8_t address) const noexcept {
  if (address == 0) return SimEndpoint{SimEndpointType::CONTROL, 64};
  switch (function_of(function)) {
    case KinectFunction::CAMERA:
      if (address != KINECT_VIDEO_ENDPOINT && address != KINECT_DEPTH_ENDPOINT) break;
      return SimEndpoint{SimEndpointType::ISO, KINECT_ISO_MAX_PACKET_BYTES, 0,
                         static_cast<std::uint8_t>(model_.model() == KinectModel::K4W ? 1 : 0)};
    case KinectFunction::AUDIO:
      if (address == AUDIO_BULK_OUT || address == AUDIO_BULK_IN)
        return SimEndpoint{SimEndpointType::BULK, AUDIO_BULK_PACKET};
      if (address == AUDIO_ISO_IN)  // listed, but the audio stream is not simulated
        return SimEndpoint{SimEndpointType::ISO, AUDIO_ISO_PACKET, 0, 0, false};
      break;
    case KinectFunction::MOTOR:
      break;
  }
  return std::nullopt;
}

SimControlReply SimKinectUsbDevice::control(std::size_t function,
                                            const drivers::UsbControlSetup& setup,
                                            std::span<std::byte> data,
                                            std::int64_t now_ns) noexcept {
  return model_.control(function_of(function), setup, data, now_ns);
}

SimControlReply SimKinectUsbDevice::bulk(std::size_t function, std::uint8_t endpoint,
                                         std::span<std::byte> data, std::int64_t now_ns) noexcept {
  return model_.bulk(function_of(function), endpoint, data, now_ns);
}

std::size_t SimKinectUsbDevice::iso_packet(std::size_t, std::uint8_t endpoint,
                                           std::int64_t microframe,
                                           std::span<std::byte> out) noexcept {
  return model_.iso_packet(endpoint, microframe, out);
}

void SimKinectUsbDevice::reset(std::size_t function, std::int64_t) noexcept {
  // The camera forgets its registers and stops streaming; the others keep their state.
  if (function_of(function) == KinectFunction::CAMERA) model_.power_cycle();
}

void SimKinectUsbDevice::unplugged(std::int64_t) noexcept {
  model_.power_cycle();
  model_.audio_power_on();
}

void SimKinectUsbDevice::replugged(std::int64_t) noexcept {
  model_.power_cycle();
  model_.audio_power_on();
}

SimDeviceEvent SimKinectUsbDevice::next_event(bool plugged) const noexcept {
  const SimKinectFaults& f = model_.faults();
  std::int64_t next = SIM_USB_NEVER;
  if (plugged && !disconnect_done_ && f.disconnect_at_ns)
    next = std::min(next, *f.disconnect_at_ns);
  if (!plugged && !reconnect_done_ && f.reconnect_at_ns) next = std::min(next, *f.reconnect_at_ns);
  if (plugged && !cancel_done_ && f.cancel_at_ns) next = std::min(next, *f.cancel_at_ns);
  return {next, true};
}

SimPlugAction SimKinectUsbDevice::take_event(std::int64_t at_ns, bool plugged) noexcept {
  const SimKinectFaults& f = model_.faults();
  if (plugged && !disconnect_done_ && f.disconnect_at_ns == at_ns) {
    disconnect_done_ = true;
    return SimPlugAction::UNPLUG;
  }
  if (!plugged && !reconnect_done_ && f.reconnect_at_ns == at_ns) {
    reconnect_done_ = true;
    return SimPlugAction::REPLUG;
  }
  if (plugged && !cancel_done_ && f.cancel_at_ns == at_ns) {
    cancel_done_ = true;
    return SimPlugAction::CANCEL_STREAMS;
  }
  return SimPlugAction::NONE;
}

}  // namespace orthoflow::simulation
