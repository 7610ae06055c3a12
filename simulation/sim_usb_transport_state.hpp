#pragma once
/// @file
/// @brief (internal) The state SimUsbTransport keeps per plugged Kinect, open handle and iso
/// stream; shared by sim_usb_transport.cpp (devices, control) and sim_usb_iso.cpp (streams, time).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "simulation/sim_usb_transport.hpp"

namespace orthoflow::simulation {

struct SimUsbTransport::Slot {
  std::unique_ptr<SimKinectDevice> device;
  bool present = true;
  std::uint32_t epoch = 1;  // bumped at every replug: older handles are dead
  bool gspca_bound = true;  // the camera's kernel driver, bound again at every plug-in
  std::array<std::uint32_t, 3> claimed_by{};  // handle id holding interface 0, per function
  bool disconnect_done = false;
  bool reconnect_done = false;
  bool cancel_done = false;
  std::uint32_t audio_generation = 0;  // of the audio function's last address assignment
};

struct SimUsbTransport::Handle {
  std::uint32_t id = 0;
  std::size_t kinect = 0;
  KinectFunction function = KinectFunction::CAMERA;
  std::uint32_t epoch = 0;
  bool claimed = false;
  bool detached = false;  // this handle detached the kernel driver: re-attach on close
  std::uint8_t alt = 0;
  std::uint32_t audio_generation = 0;  // audio handles die when the function re-enumerates
};

struct SimUsbTransport::Stream {
  std::uint32_t handle = 0;
  std::size_t kinect = 0;
  std::uint8_t endpoint = 0;
  drivers::UsbIsoConfig config{};
  drivers::UsbIsoCallback on_packet;
  std::vector<std::byte> buffer;     // transfers x packets x packet_size
  std::vector<std::size_t> lengths;  // of the transfer being filled
  std::vector<drivers::UsbPacketStatus> statuses;
  std::array<std::byte, KINECT_ISO_MAX_PACKET_BYTES> scratch{};  // when packet_size < 1920
  std::int64_t first_mf = 0;  // first microframe of the oldest in-flight transfer
  std::size_t filled = 0;     // its packets filled so far
  std::uint64_t completed =
      0;              // transfers completed: the oldest one uses buffer slot completed % T
  bool alive = true;  // false once its transfers came back NO_DEVICE or CANCELLED
  drivers::UsbIsoStats stats{};
  [[nodiscard]] std::int64_t completion_ns() const noexcept {
    return (first_mf + static_cast<std::int64_t>(config.packets_per_transfer)) * USB_MICROFRAME_NS;
  }
};

}  // namespace orthoflow::simulation
