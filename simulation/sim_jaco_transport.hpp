#pragma once
/// @file
/// @brief SimJacoTransport: the UsbTransport seam (drivers/usb_transport.hpp) over simulated Kinova
/// JACO arms (sim_jaco_arm.hpp) on simulated time, so the JACO driver runs end to end on a machine
/// without USB (specs/USB_TESTING.md 3.3). Implements the documented protocol (specs/JACO.md 1, 2,
/// 4); never compared with hardware.
///
/// Devices: every arm enumerates as vendor 0x22CD, product 0x0000, full speed, one interface (0),
/// interrupt endpoints 0x02 OUT and 0x82 IN of 64 bytes; bcdDevice 0x0100 and the serial string
/// SimJacoConfig::usb_serial, empty by default [I: JACO.md names neither; libkindrv tells arms
/// apart by client name]. The port path is
/// the config's root port; addresses are handed out per bus from first_address, never reused.
///
/// Time: clock() is a drivers::ManualClock (owned, or given), and only this transport moves it
/// (a given clock may also be moved by hand: every call first catches up with it):
/// - interrupt() takes transfer_latency (default 1 ms, full-speed interrupt polling) and steps the
///   arms meanwhile: an OUT reaches the arm at the end of it; an IN with a reply pending returns it
///   at the end of it; an IN with nothing pending waits its whole timeout (infinite_wait when the
///   timeout is 0) and returns TIMEOUT;
/// - handle_events(t) advances by t (t = 0: only catches up), stepping the arms; run_for(d) too.
/// The arms run their 10 ms cycle on this clock whether or not they are plugged in.
///
/// Strict behaviour, stricter than libusb where libusb is lenient (documented choices):
/// - only interface 0 exists (NOT_FOUND otherwise), alternate setting 0 only; claim_interface is
///   BUSY if this or another handle holds the claim; release_interface / set_alt_setting NOT_FOUND
///   without the claim; no kernel driver is ever bound (kernel_driver_active() is false, detach /
///   attach NOT_FOUND);
/// - interrupt(): NOT_FOUND for any endpoint but 0x02 / 0x82 or without the claim; an OUT must be
///   exactly 64 bytes (else INVALID_PARAM, nothing sent: the firmware only takes whole packets);
///   an IN buffer under 64 bytes is OVERFLOW (the reply is lost, as on libusb); a bigger one gets
///   64 bytes;
/// - control(): NOT_SUPPORTED (the simulated arm answers no EP0 requests; the driver needs none);
///   bulk(), max_iso_packet_size(), start_iso(), stop_iso(), iso_stats(): NOT_FOUND (the arm has
///   no bulk or isochronous endpoint);
/// - reset_device() keeps the handle and the arm's state, and drops the arm's pending replies;
///   clear_halt() accepts 0, 0x02 and 0x82;
/// - unplug (unplug(), or SimJacoFaults::unplug_at_ns, once) pulls the cable: the arm leaves
///   enumerate, a transfer in progress (an IN waiting, the latency of any transfer) ends with
///   NO_DEVICE at that moment, and every handle opened before answers NO_DEVICE, even after the
///   replug. The arm itself keeps its power: its FIFO and latched joystick keep acting (JACO.md
///   11). replug() puts it back at a new address with its pending replies dropped (the stale
///   replies fault queues its replies again); SimJacoArm::power_cycle() is the power switch.
/// Threading: one thread, like every UsbTransport. Determinism: same calls, same bytes and times.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "drivers/monotonic_clock.hpp"
#include "drivers/usb_transport.hpp"
#include "simulation/sim_jaco_arm.hpp"

namespace orthoflow::simulation {

/// @brief Timing of the simulated host. Plain data with defaults.
struct SimJacoTransportConfig {
  std::chrono::nanoseconds transfer_latency{1'000'000};  ///< every interrupt transfer takes this
  std::chrono::milliseconds infinite_wait{5'000};  ///< an IN with timeout 0 and no reply waits this
  std::uint8_t first_address = 2;  ///< addresses are handed out from here, per bus, never reused
};

/// @brief UsbTransport over simulated JACO arms. @note Not thread-safe (one USB thread).
class SimJacoTransport final : public drivers::UsbTransport {
 public:
  /// @brief A transport with its own ManualClock starting at 0. @pre none.
  explicit SimJacoTransport(SimJacoTransportConfig config = {});
  /// @brief A transport moving @p clock. @pre @p clock outlives the transport.
  explicit SimJacoTransport(drivers::ManualClock& clock, SimJacoTransportConfig config = {});
  ~SimJacoTransport() override;

  /// @brief Plugs in (and powers on) an arm now; returns its index. @pre Its bus has addresses
  /// left. @note Allocates (call at test set-up).
  std::size_t add_arm(SimJacoConfig config);
  /// @brief The device model of arm @p index (ground truth, faults). @pre index < arm_count().
  [[nodiscard]] SimJacoArm& arm(std::size_t index);
  [[nodiscard]] std::size_t arm_count() const noexcept { return slots_.size(); }
  /// @brief False between an unplug and the replug. @pre index < arm_count().
  [[nodiscard]] bool present(std::size_t index) const;
  /// @brief Pulls arm @p index's cable now. No-op if absent. @pre index < arm_count().
  void unplug(std::size_t index);
  /// @brief Plugs it back now at a new address. No-op if present. @pre index < arm_count().
  void replug(std::size_t index);
  /// @brief Advances simulated time by @p duration, stepping the arms. @pre duration >= 0.
  void run_for(std::chrono::nanoseconds duration);
  /// @brief The simulated clock, to read or to move by hand (the next call catches up).
  [[nodiscard]] drivers::ManualClock& manual_clock() noexcept { return *clock_; }

  [[nodiscard]] Result<std::vector<drivers::UsbDeviceInfo>, drivers::UsbError> enumerate(
      std::uint16_t vendor, std::optional<std::uint16_t> product) override;
  [[nodiscard]] Result<drivers::UsbDeviceHandle, drivers::UsbError> open(
      const drivers::UsbDeviceInfo& device) override;
  [[nodiscard]] Result<void, drivers::UsbError> claim_interface(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> release_interface(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> set_alt_setting(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number,
      std::uint8_t alt_setting) override;
  [[nodiscard]] Result<bool, drivers::UsbError> kernel_driver_active(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> detach_kernel_driver(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> attach_kernel_driver(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> reset_device(
      const drivers::UsbDeviceHandle& handle) override;
  [[nodiscard]] Result<void, drivers::UsbError> clear_halt(const drivers::UsbDeviceHandle& handle,
                                                           std::uint8_t endpoint) override;
  [[nodiscard]] Result<std::size_t, drivers::UsbError> control(
      const drivers::UsbDeviceHandle& handle, const drivers::UsbControlSetup& setup,
      std::span<std::byte> data, drivers::UsbTimeout timeout) override;
  [[nodiscard]] Result<std::size_t, drivers::UsbError> bulk(const drivers::UsbDeviceHandle& handle,
                                                            std::uint8_t endpoint,
                                                            std::span<std::byte> data,
                                                            drivers::UsbTimeout timeout) override;
  [[nodiscard]] Result<std::size_t, drivers::UsbError> interrupt(
      const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint, std::span<std::byte> data,
      drivers::UsbTimeout timeout) override;
  [[nodiscard]] Result<std::size_t, drivers::UsbError> max_iso_packet_size(
      const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint) override;
  [[nodiscard]] Result<void, drivers::UsbError> start_iso(
      const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint,
      const drivers::UsbIsoConfig& config, drivers::UsbIsoCallback on_packet) override;
  [[nodiscard]] Result<void, drivers::UsbError> stop_iso(const drivers::UsbDeviceHandle& handle,
                                                         std::uint8_t endpoint) override;
  [[nodiscard]] Result<drivers::UsbIsoStats, drivers::UsbError> iso_stats(
      const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint) const override;
  [[nodiscard]] Result<void, drivers::UsbError> handle_events(drivers::UsbTimeout timeout) override;
  [[nodiscard]] const drivers::MonotonicClock& clock() const noexcept override { return *clock_; }

 protected:
  void close_device(std::uint32_t id) noexcept override;

 private:
  struct Slot {
    std::unique_ptr<SimJacoArm> arm;
    bool present = true;
    std::uint32_t epoch = 1;  // bumped at every replug: older handles are dead
    std::uint8_t address = 0;
    std::uint32_t claimed_by = 0;  // handle id holding interface 0
    bool unplug_fault_done = false;
  };
  struct Handle {
    std::uint32_t id = 0;
    std::size_t arm = 0;
    std::uint32_t epoch = 0;
    bool claimed = false;
  };

  [[nodiscard]] Result<Handle*, drivers::UsbError> lookup(const drivers::UsbDeviceHandle& handle,
                                                          const char* operation,
                                                          bool need_device) const;
  [[nodiscard]] Result<Handle*, drivers::UsbError> interface_of(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number,
      const char* operation) const;
  [[nodiscard]] bool alive(const Handle& h) const noexcept;
  [[nodiscard]] drivers::UsbDeviceInfo info(const Slot& slot) const noexcept;
  void assign_address(Slot& slot);
  void run_until(std::int64_t t_ns);
  bool run_while_alive(const Handle& h, std::int64_t t_ns);
  void apply_unplug_faults(std::int64_t t_ns);

  SimJacoTransportConfig config_;
  std::unique_ptr<drivers::ManualClock> owned_clock_;
  drivers::ManualClock* clock_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<std::unique_ptr<Handle>> handles_;
  std::array<std::uint8_t, 256> next_address_{};  // per bus
  std::uint32_t next_handle_id_ = 1;
};

}  // namespace orthoflow::simulation
