#pragma once
/// @file
/// @brief SimKinectUsbDevice: a simulated Kinect v1 (sim_kinect_device.hpp) as a device of the
/// simulated USB host (sim_usb_host.hpp). It adds only what is the Kinect's own:
/// - three functions behind an internal hub that takes the first of its four addresses: camera
///   (function 0), motor (1, model 1414 only) and audio (2, if with_audio), at hub ports 1, 3, 2;
/// - interface 0 on each, with alternate settings 0, plus 1 on the K4W camera; the camera's
///   kernel driver (gspca_kinect) is bound at every plug-in;
/// - endpoints: EP0 control on every function; the camera's iso 0x81 (video) and 0x82 (depth) of
///   1920 bytes (K4W: in alternate setting 1 only); the audio function's bulk 0x01 / 0x81 and its
///   iso 0x82 of 524 bytes, listed but not simulated;
/// - the audio function re-enumerates on its own after a firmware execute (a new generation: its
///   handles die, and it gets a new address once it is back);
/// - a port reset power-cycles the camera; unplug and replug power-cycle the Kinect and return
///   the audio function to its bootloader;
/// - the fault times of SimKinectFaults as waking events: disconnect_at_ns (unplug),
///   reconnect_at_ns (replug), cancel_at_ns (in-flight iso transfers come back CANCELLED), each
///   once.
/// Threading: the host's thread. Determinism: that of SimKinectDevice.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>

#include "simulation/devices/sim_kinect_device.hpp"
#include "simulation/devices/sim_usb_device.hpp"

namespace orthoflow::simulation {

/// @brief A Kinect on the simulated host. @note Not copyable; owns its SimKinectDevice.
class SimKinectUsbDevice final : public SimUsbDevice {
 public:
  /// @brief A Kinect built from @p config. @pre As SimKinectDevice's constructor.
  explicit SimKinectUsbDevice(SimKinectConfig config) : model_(std::move(config)) {}

  /// @brief The device model: registers, raw frames, motor, audio, faults. @pre none.
  [[nodiscard]] SimKinectDevice& model() noexcept { return model_; }
  [[nodiscard]] const SimKinectDevice& model() const noexcept { return model_; }

  // ---- SimUsbDevice (sim_usb_device.hpp documents each; the header comment above says how) ---
  [[nodiscard]] std::uint8_t bus() const noexcept override { return model_.config().bus; }
  [[nodiscard]] std::size_t function_count() const noexcept override { return 3; }
  [[nodiscard]] std::size_t hub_addresses() const noexcept override { return 1; }
  [[nodiscard]] bool present(std::size_t function, std::int64_t now_ns) const noexcept override;
  [[nodiscard]] drivers::UsbDeviceInfo info(std::size_t function) const noexcept override;
  void set_address(std::size_t function, std::uint8_t address) noexcept override;
  [[nodiscard]] std::uint32_t generation(std::size_t function) const noexcept override;
  [[nodiscard]] std::uint8_t alt_settings(std::size_t function,
                                          std::uint8_t interface) const noexcept override;
  [[nodiscard]] bool kernel_driver(std::size_t function,
                                   std::uint8_t interface) const noexcept override;
  [[nodiscard]] std::optional<SimEndpoint> endpoint(std::size_t function,
                                                    std::uint8_t address) const noexcept override;

  SimControlReply control(std::size_t function, const drivers::UsbControlSetup& setup,
                          std::span<std::byte> data, std::int64_t now_ns) noexcept override;
  SimControlReply bulk(std::size_t function, std::uint8_t endpoint, std::span<std::byte> data,
                       std::int64_t now_ns) noexcept override;
  std::size_t iso_packet(std::size_t function, std::uint8_t endpoint, std::int64_t microframe,
                         std::span<std::byte> out) noexcept override;

  void reset(std::size_t function, std::int64_t now_ns) noexcept override;
  void unplugged(std::int64_t now_ns) noexcept override;
  void replugged(std::int64_t now_ns) noexcept override;
  [[nodiscard]] SimDeviceEvent next_event(bool plugged) const noexcept override;
  SimPlugAction take_event(std::int64_t at_ns, bool plugged) noexcept override;

 private:
  SimKinectDevice model_;
  bool disconnect_done_ = false;
  bool reconnect_done_ = false;
  bool cancel_done_ = false;
};

}  // namespace orthoflow::simulation
