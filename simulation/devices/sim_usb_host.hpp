#pragma once
/// @file
/// @brief SimUsbHost: the UsbTransport seam (drivers/usb/usb_transport.hpp) over simulated USB
/// devices (sim_usb_device.hpp: the Kinect v1, the JACO) on simulated time, so drivers run end to
/// end on a machine without USB (specs/USB_TESTING.md 3.3). Any mix of devices shares one host: a
/// Kinect and an arm on one bus, as on the robot. It keeps, once for every device: the plugged
/// devices, their functions' addresses (per bus from first_address, never reused; a function that
/// re-enumerates gets a new one), handles (ids never reused; an epoch per plug-in, so a handle of
/// an unplugged device answers NO_DEVICE forever), interface claims, alternate settings,
/// kernel-driver binding, plug / unplug / replug, iso streams, transfer timing and the simulated
/// clock. The devices add only their descriptors, transfers and events. Never compared with
/// hardware.
///
/// Time: clock() is a drivers::ManualClock (owned, or given), and only this host moves it (a
/// given clock may also be moved by hand: events then run late, never backwards). Whenever it
/// moves, every device is stepped to it (SimUsbDevice::advance: the JACO's 10 ms cycle).
/// - handle_events(t) advances to the next waking event (an iso transfer completing after its
///   packets_per_transfer microframes of 125 us, or a device's waking fault time) or by t,
///   whichever comes first, and runs everything due; t = 0 delivers only what is due now. Events
///   that do not wake (the JACO's unplug fault) happen as time passes them.
/// - control() takes control_latency and pumps events meanwhile: the device answers at its start;
///   one the device stalls (TIMEOUT) waits its whole timeout (infinite_wait when the timeout is 0)
///   and returns TIMEOUT; a device unplugged meanwhile gives NO_DEVICE at the end. bulk() the
///   same, on a claimed interface's bulk endpoint.
/// - interrupt() takes interrupt_latency: an OUT reaches the device at the end of it; an IN with a
///   packet pending returns it at the end of it; an IN with nothing pending waits its whole
///   timeout (infinite_wait when 0) and returns TIMEOUT; an unplug on the way ends the transfer
///   at that moment with NO_DEVICE. An IN buffer smaller than the packet is OVERFLOW (lost).
/// - run_for(d) (tests) pumps until now + d.
/// Iso streams: start_iso allocates transfers x packets x packet_size bytes; transfers complete
/// back to back, each packet slot holding that microframe's device packet (idle microframes give
/// zero-length COMPLETED packets), generated only once its microframe has elapsed (and before any
/// request reaches a device), and are resubmitted at once. A device packet longer than packet_size
/// is an OVERFLOW packet (length 0). Unplug: every in-flight transfer comes back NO_DEVICE packet
/// by packet and is not resubmitted; an unrequested cancel does the same with CANCELLED. stop_iso
/// stops delivery at once (the simulator never leaks transfers). On a tie, transfer completions
/// come before device events, and devices' events in the order the devices were added.
///
/// Strict behaviour, stricter than libusb where libusb is lenient (documented choices):
/// - only the interfaces a function lists exist (NOT_FOUND otherwise), with their alternate
///   settings; claim_interface is BUSY if this or another handle holds the claim, or while a kernel
///   driver (bound at every plug-in where the device says so) is attached;
/// - release_interface / set_alt_setting: NOT_FOUND if not claimed, BUSY while a stream runs;
/// - detach_kernel_driver: NOT_FOUND if none is attached; attach: NOT_FOUND where the function has
///   no kernel driver, BUSY if attached or claimed; a detached driver is re-attached on close;
/// - control: NOT_SUPPORTED on a function without a control endpoint; bulk / interrupt / start_iso:
///   NOT_FOUND for an endpoint the function lacks (or lists without simulating), of another type,
///   or on an unclaimed interface; start_iso also NOT_FOUND outside the endpoint's alternate
///   setting, BUSY if any handle streams that endpoint; max_iso_packet_size: NOT_FOUND but for
///   iso endpoints; clear_halt: endpoint 0 or a simulated endpoint, BUSY while it streams;
/// - reset_device keeps the handle (same descriptors, libusb's rule), BUSY while a stream runs;
/// - a handle of a device that was unplugged answers NO_DEVICE, even after the replug (at new
///   addresses: enumerate and open again); stop_iso, iso_stats and close still work on it.
/// Threading: one thread, like every UsbTransport; a callback must not call the host (OF_ENFORCE).
/// Determinism: same calls, same bytes and times.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "drivers/usb/monotonic_clock.hpp"
#include "drivers/usb/usb_transport.hpp"
#include "simulation/devices/sim_usb_device.hpp"

namespace orthoflow::simulation {

/// @brief Timing and addressing of the simulated host. Plain data with defaults.
struct SimUsbHostConfig {
  std::chrono::nanoseconds control_latency{50'000};       ///< every control and bulk transfer
  std::chrono::nanoseconds interrupt_latency{1'000'000};  ///< every interrupt transfer (1 ms)
  std::chrono::milliseconds infinite_wait{5'000};  ///< timeout 0 without an answer waits this
  std::uint8_t first_address = 2;  ///< addresses are handed out from here, per bus, never reused
};

/// @brief UsbTransport over simulated devices. @note Not thread-safe (one USB thread).
class SimUsbHost : public drivers::UsbTransport {
 public:
  /// @brief A host with its own ManualClock starting at 0. @pre none.
  explicit SimUsbHost(SimUsbHostConfig config = {});
  /// @brief A host moving @p clock. @pre @p clock outlives the host.
  explicit SimUsbHost(drivers::ManualClock& clock, SimUsbHostConfig config = {});
  ~SimUsbHost() override;

  /// @brief Plugs @p device in now (its kernel drivers bound, its functions addressed); returns
  /// its index. @pre device non-null, its bus has addresses left. @note Allocates (set-up time).
  std::size_t add_device(std::unique_ptr<SimUsbDevice> device);
  /// @brief Device @p index. @pre index < device_count().
  [[nodiscard]] SimUsbDevice& device(std::size_t index);
  [[nodiscard]] std::size_t device_count() const noexcept { return slots_.size(); }
  /// @brief False between an unplug and the replug. @pre index < device_count().
  [[nodiscard]] bool device_present(std::size_t index) const;
  /// @brief Pulls device @p index's cable now (after delivering what is due): its streams fail
  /// NO_DEVICE, it leaves enumerate. No-op if absent. @pre index < device_count().
  void unplug_device(std::size_t index);
  /// @brief Plugs it back now at new addresses (a new epoch, kernel drivers bound again). No-op if
  /// present. @pre index < device_count().
  void replug_device(std::size_t index);
  /// @brief Pumps events (running callbacks, stepping devices) until simulated now + @p duration.
  /// @pre duration >= 0.
  void run_for(std::chrono::nanoseconds duration);
  /// @brief The simulated clock, to read or to move by hand (then handle_events(0) delivers). @pre
  /// none.
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
  struct Function;
  struct Slot;
  struct Handle;
  struct Stream;

  // Handles and interfaces (sim_usb_host.cpp, sim_usb_host_interfaces.cpp).
  Result<Handle*, drivers::UsbError> lookup(const drivers::UsbDeviceHandle& handle,
                                            const char* operation, bool need_device) const;
  Result<Handle*, drivers::UsbError> interface_of(const drivers::UsbDeviceHandle& handle,
                                                  std::uint8_t interface_number,
                                                  const char* operation) const;
  [[nodiscard]] bool alive(const Handle& h) const noexcept;
  [[nodiscard]] std::optional<SimEndpoint> endpoint_of(const Handle& h, std::uint8_t endpoint,
                                                       SimEndpointType type) const noexcept;
  [[nodiscard]] bool streaming(const Handle& h) const noexcept;
  [[nodiscard]] Stream* find_stream(std::uint32_t handle_id, std::uint8_t endpoint) const noexcept;
  void assign_addresses(Slot& slot);
  void refresh_functions(Slot& slot);
  void sync_generations(Slot& slot) noexcept;
  void enforce_not_in_callback() const noexcept;
  // Transfers (sim_usb_host_transfers.cpp).
  Result<std::size_t, drivers::UsbError> finish_request(const Handle& h, SimControlReply reply,
                                                        drivers::UsbTimeout timeout,
                                                        const char* operation);
  Result<std::size_t, drivers::UsbError> interrupt_in(const Handle& h, std::uint8_t endpoint,
                                                      std::span<std::byte> data,
                                                      drivers::UsbTimeout timeout);
  [[nodiscard]] std::int64_t wait_ns(drivers::UsbTimeout timeout) const noexcept;
  // Time and streams (sim_usb_host_time.cpp, sim_usb_host_iso.cpp).
  void run_until(std::int64_t target_ns);
  bool run_while_alive(const Handle& h, std::int64_t target_ns);
  [[nodiscard]] std::int64_t next_event_ns(bool waking_only) const noexcept;
  bool run_next_event(std::int64_t limit_ns);
  bool run_device_event(std::int64_t at_ns);
  void step_devices() noexcept;
  void advance_clock(std::int64_t t_ns) noexcept;
  void sync_streams(std::int64_t now_ns) noexcept;
  void fill(Stream& s, std::int64_t microframe_limit) noexcept;
  void complete(Stream& s);
  void fail_streams(std::size_t slot, drivers::UsbPacketStatus status);
  void fail_stream(Stream& s, drivers::UsbPacketStatus status);

  SimUsbHostConfig config_;
  std::unique_ptr<drivers::ManualClock> owned_clock_;
  drivers::ManualClock* clock_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<std::unique_ptr<Handle>> handles_;
  std::vector<std::unique_ptr<Stream>> streams_;
  std::array<std::uint8_t, 256> next_address_{};  // per bus
  std::uint32_t next_handle_id_ = 1;
  bool in_callback_ = false;
};

}  // namespace orthoflow::simulation
