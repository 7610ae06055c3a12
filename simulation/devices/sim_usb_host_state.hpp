#pragma once
/// @file
/// @brief (internal) The state SimUsbHost keeps per plugged device, USB function, open handle and
/// iso stream; shared by its sim_usb_host*.cpp files.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "simulation/devices/sim_usb_host.hpp"

namespace orthoflow::simulation {

struct SimUsbHost::Function {
  std::uint32_t generation = 0;  // of the last address assignment (re-enumeration)
  std::array<std::uint32_t, SIM_USB_MAX_INTERFACES> claimed_by{};  // handle id per interface
  std::array<bool, SIM_USB_MAX_INTERFACES> kernel_bound{};         // bound again at plug-in
};

struct SimUsbHost::Slot {
  std::unique_ptr<SimUsbDevice> device;
  bool present = true;
  std::uint32_t epoch = 1;  // bumped at every replug: older handles are dead
  std::vector<Function> functions;
};

struct SimUsbHost::Handle {
  std::uint32_t id = 0;
  std::size_t slot = 0;
  std::size_t function = 0;
  std::uint32_t epoch = 0;
  std::uint32_t generation = 0;  // handles die when the function re-enumerates
  std::uint8_t claimed = 0;      // bit i: interface i claimed by this handle
  std::uint8_t detached = 0;  // bit i: this handle detached its kernel driver: re-attach on close
  std::array<std::uint8_t, SIM_USB_MAX_INTERFACES> alt{};
  [[nodiscard]] bool claims(std::uint8_t interface) const noexcept {
    return interface < SIM_USB_MAX_INTERFACES && ((claimed >> interface) & 1U) != 0;
  }
};

struct SimUsbHost::Stream {
  std::uint32_t handle = 0;
  std::size_t slot = 0;
  std::size_t function = 0;
  std::uint8_t endpoint = 0;
  drivers::UsbIsoConfig config{};
  drivers::UsbIsoCallback on_packet;
  std::vector<std::byte> buffer;     // transfers x packets x packet_size
  std::vector<std::size_t> lengths;  // of the transfer being filled
  std::vector<drivers::UsbPacketStatus> statuses;
  std::vector<std::byte> scratch;  // the device's max packet, when packet_size is smaller
  std::int64_t first_mf = 0;       // first microframe of the oldest in-flight transfer
  std::size_t filled = 0;          // its packets filled so far
  std::uint64_t completed = 0;     // transfers completed: the oldest uses slot completed % T
  bool alive = true;               // false once its transfers came back NO_DEVICE or CANCELLED
  drivers::UsbIsoStats stats{};
  [[nodiscard]] std::int64_t completion_ns() const noexcept {
    return (first_mf + static_cast<std::int64_t>(config.packets_per_transfer)) * USB_MICROFRAME_NS;
  }
};

}  // namespace orthoflow::simulation
