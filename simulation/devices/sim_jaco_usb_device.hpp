#pragma once
/// @file
/// @brief SimJacoUsbDevice: a simulated Kinova JACO (sim_jaco_arm.hpp) as a device of the
/// simulated USB host (sim_usb_host.hpp), implementing specs/JACO.md 1, 2, 4. It adds only what
/// is the arm's own:
/// - one function: vendor 0x22CD, product 0x0000, full speed, bcdDevice 0x0100 and the serial
///   string SimJacoConfig::usb_serial, empty by default [I: JACO.md names neither; libkindrv tells
///   arms apart by client name]; the port path is the config's root port;
/// - interface 0 with alternate setting 0 only, no kernel driver, no control endpoint (the arm
///   answers no EP0 requests: control() is NOT_SUPPORTED; the driver needs none);
/// - interrupt endpoints 0x02 OUT and 0x82 IN of 64 bytes; an OUT must be one whole packet (the
///   firmware only takes whole packets); no bulk or isochronous endpoint;
/// - every OUT goes to SimJacoArm::receive, every IN takes its oldest reply;
/// - a port reset keeps the arm's state and drops its pending replies; unplug leaves the arm
///   running (the cable is gone, not the power: its FIFO and latched joystick keep acting,
///   JACO.md 11); replug drops its pending replies (the stale replies fault queues them again);
///   SimJacoArm::power_cycle() is the power switch;
/// - the 10 ms cycle, stepped whenever the host's clock moves, plugged in or not;
/// - SimJacoFaults::unplug_at_ns as an event that happens as time passes it (it does not end a
///   handle_events() wait), once.
/// Threading: the host's thread. Determinism: that of SimJacoArm.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "simulation/devices/sim_jaco_arm.hpp"
#include "simulation/devices/sim_usb_device.hpp"

namespace orthoflow::simulation {

/// @brief A JACO on the simulated host. @note Not copyable; owns its SimJacoArm (on the heap:
/// about 110 KB).
class SimJacoUsbDevice final : public SimUsbDevice {
 public:
  /// @brief An arm built from @p config, powered on at @p start_ns. @pre As SimJacoArm's.
  SimJacoUsbDevice(SimJacoConfig config, std::int64_t start_ns);

  /// @brief The device model: ground truth, counters, faults. @pre none.
  [[nodiscard]] SimJacoArm& arm() noexcept { return *arm_; }
  [[nodiscard]] const SimJacoArm& arm() const noexcept { return *arm_; }

  // ---- SimUsbDevice (sim_usb_device.hpp documents each; the header comment above says how) ---
  [[nodiscard]] std::uint8_t bus() const noexcept override { return arm_->config().bus; }
  [[nodiscard]] std::size_t function_count() const noexcept override { return 1; }
  [[nodiscard]] bool present(std::size_t, std::int64_t) const noexcept override { return true; }
  [[nodiscard]] drivers::UsbDeviceInfo info(std::size_t function) const noexcept override;
  void set_address(std::size_t, std::uint8_t address) noexcept override { address_ = address; }
  [[nodiscard]] std::uint8_t alt_settings(std::size_t function,
                                          std::uint8_t interface) const noexcept override;
  [[nodiscard]] std::optional<SimEndpoint> endpoint(std::size_t function,
                                                    std::uint8_t address) const noexcept override;

  void interrupt_out(std::size_t function, std::uint8_t endpoint, std::span<const std::byte> packet,
                     std::int64_t now_ns) noexcept override;
  [[nodiscard]] bool interrupt_pending(std::size_t function,
                                       std::uint8_t endpoint) const noexcept override;
  std::size_t interrupt_in(std::size_t function, std::uint8_t endpoint,
                           std::span<std::byte> packet) noexcept override;

  void reset(std::size_t function, std::int64_t now_ns) noexcept override;
  void replugged(std::int64_t now_ns) noexcept override;
  void advance(std::int64_t now_ns) noexcept override { arm_->step(now_ns); }
  [[nodiscard]] SimDeviceEvent next_event(bool plugged) const noexcept override;
  SimPlugAction take_event(std::int64_t at_ns, bool plugged) noexcept override;

 private:
  std::unique_ptr<SimJacoArm> arm_;
  std::uint8_t address_ = 0;
  bool unplug_done_ = false;
};

}  // namespace orthoflow::simulation
