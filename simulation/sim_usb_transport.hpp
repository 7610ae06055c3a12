#pragma once
/// @file
/// @brief SimUsbTransport: the UsbTransport seam (drivers/usb_transport.hpp) over simulated Kinects
/// (sim_kinect_device.hpp) on simulated time, so the Kinect driver runs end to end on a machine
/// without USB (specs/USB_TESTING.md 3.3). Implements the documented protocol; never compared
/// with hardware.
///
/// Time: clock() is a drivers::ManualClock (owned, or given), and only this transport moves it:
/// - handle_events(t) advances to the next event (an iso transfer completing after its
///   packets_per_transfer microframes of 125 us, or a fault time) or by t, whichever comes first,
///   and runs the callbacks of everything due; t = 0 delivers only what is due now;
/// - control() takes control_latency (default 50 us) and pumps events meanwhile; a stalled control
///   transfer waits its whole timeout (infinite_wait when the timeout is 0) and returns TIMEOUT;
/// - run_for(d) (tests) pumps until now + d.
/// Iso streams: start_iso allocates transfers x packets x packet_size bytes; transfers complete
/// back to back, each packet slot holding that microframe's device packet (idle microframes give
/// zero-length COMPLETED packets), and are resubmitted at once. A device packet longer than
/// packet_size is an OVERFLOW packet (length 0). Unplug: every in-flight transfer comes back
/// NO_DEVICE packet by packet and is not resubmitted; an unrequested cancel does the same with
/// CANCELLED. stop_iso stops delivery at once (the simulator never leaks transfers).
///
/// Strict behaviour, stricter than libusb where libusb is lenient (documented choices):
/// - only interface 0 exists (NOT_FOUND otherwise); alternate settings: 0, plus 1 on the K4W
/// camera;
/// - claim_interface: BUSY if this or another handle holds the claim, or while the camera's kernel
///   driver (gspca_kinect, bound at plug-in: kernel_driver_active() is true) is attached;
/// - release_interface / set_alt_setting: NOT_FOUND if not claimed, BUSY while a stream runs;
/// - start_iso: NOT_FOUND for an endpoint the function lacks, an unclaimed interface, or a K4W
///   camera not in alternate setting 1; BUSY if any handle streams that endpoint;
/// - detach_kernel_driver: NOT_FOUND if none is attached; attach: BUSY if attached or claimed;
/// - bulk: only the audio function's 0x01 / 0x81 on a claimed interface (else NOT_FOUND); it takes
///   control_latency; the device's TIMEOUT (an IN with nothing to send, a stall fault) waits the
///   whole timeout; interrupt: NOT_FOUND;
/// - the audio function re-enumerates on its own after a firmware execute (sim_kinect_device.hpp):
///   while away it is not enumerated and its handles answer NO_DEVICE; it comes back at a new
///   address (handed out when first seen by enumerate / open);
/// - a handle of a device that was unplugged answers NO_DEVICE, even after the Kinect is back
///   (at new addresses: enumerate and open again); stop_iso, iso_stats and close still work on it.
/// Threading: one thread, like every UsbTransport. Determinism: same calls, same bytes and times.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "drivers/monotonic_clock.hpp"
#include "drivers/usb_transport.hpp"
#include "simulation/sim_kinect_device.hpp"

namespace orthoflow::simulation {

/// @brief Timing of the simulated host. Plain data with defaults.
struct SimUsbTransportConfig {
  std::chrono::nanoseconds control_latency{50'000};  ///< every control transfer takes this long
  std::chrono::milliseconds infinite_wait{
      5'000};                      ///< a stall with timeout 0 waits this, then TIMEOUT
  std::uint8_t first_address = 2;  ///< addresses are handed out from here, per bus, never reused
};

/// @brief UsbTransport over simulated Kinects. @note Not thread-safe (one USB thread).
class SimUsbTransport final : public drivers::UsbTransport {
 public:
  /// @brief A transport with its own ManualClock starting at 0. @pre none.
  explicit SimUsbTransport(SimUsbTransportConfig config = {});
  /// @brief A transport moving @p clock. @pre @p clock outlives the transport.
  explicit SimUsbTransport(drivers::ManualClock& clock, SimUsbTransportConfig config = {});
  ~SimUsbTransport() override;

  /// @brief Plugs in a Kinect now; returns its index. Its fault times apply from now on.
  /// @pre Its bus has addresses left. @note Allocates (call at test set-up).
  std::size_t add_kinect(SimKinectConfig config);
  /// @brief The device model of Kinect @p index (registers, raw frames, motor, faults).
  /// @pre index < kinect_count().
  [[nodiscard]] SimKinectDevice& kinect(std::size_t index);
  [[nodiscard]] std::size_t kinect_count() const noexcept { return slots_.size(); }
  /// @brief False between an unplug and the replug.
  [[nodiscard]] bool present(std::size_t index) const;
  /// @brief Unplugs Kinect @p index now (as faults.disconnect_at_ns would). No-op if absent.
  void unplug(std::size_t index);
  /// @brief Plugs it back now at new addresses, in power-on state. No-op if present.
  void replug(std::size_t index);
  /// @brief Pumps events (running callbacks) until simulated now + @p duration. @pre duration >= 0.
  void run_for(std::chrono::nanoseconds duration);
  /// @brief The simulated clock, to read or to move by hand (then handle_events(0) delivers).
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
  struct Slot;
  struct Handle;
  struct Stream;

  Result<Handle*, drivers::UsbError> lookup(const drivers::UsbDeviceHandle& handle,
                                            const char* operation, bool need_device) const;
  Result<Handle*, drivers::UsbError> interface_of(const drivers::UsbDeviceHandle& handle,
                                                  std::uint8_t interface_number,
                                                  const char* operation) const;
  [[nodiscard]] bool streaming(const Handle& h) const noexcept;
  [[nodiscard]] Stream* find_stream(std::uint32_t handle_id, std::uint8_t endpoint) const noexcept;
  void assign_addresses(Slot& slot);
  void refresh_audio(Slot& slot);
  void run_until(std::int64_t target_ns);
  [[nodiscard]] std::int64_t next_event_ns() const noexcept;
  bool run_next_event(std::int64_t limit_ns);
  void sync_streams(std::int64_t now_ns) noexcept;
  void fill(Stream& s, std::int64_t microframe_limit) noexcept;
  void complete(Stream& s);
  void fail_stream(Stream& s, drivers::UsbPacketStatus status);
  void advance_clock(std::int64_t t_ns) noexcept;
  void enforce_not_in_callback() const noexcept;

  SimUsbTransportConfig config_;
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
