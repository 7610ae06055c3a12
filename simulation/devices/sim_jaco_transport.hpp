#pragma once
/// @file
/// @brief SimJacoTransport: the simulated USB host (sim_usb_host.hpp) set up for simulated Kinova
/// JACO arms (sim_jaco_usb_device.hpp), with arm-numbered accessors, so the JACO driver runs end to
/// end on a machine without USB (specs/USB_TESTING.md 3.3). Implements the documented protocol
/// (specs/JACO.md 1, 2, 4); never compared with hardware.
///
/// Devices: every arm enumerates as vendor 0x22CD, product 0x0000, full speed, one interface (0),
/// interrupt endpoints 0x02 OUT and 0x82 IN of 64 bytes; bcdDevice 0x0100 and the serial string
/// SimJacoConfig::usb_serial, empty by default [I]. The port path is the config's root port;
/// addresses are handed out per bus from first_address, never reused.
///
/// Time: clock() is a drivers::ManualClock (owned, or given), and only this transport moves it
/// (a given clock may also be moved by hand: the next call catches up with it):
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
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "drivers/usb/monotonic_clock.hpp"
#include "simulation/devices/sim_jaco_arm.hpp"
#include "simulation/devices/sim_usb_host.hpp"

namespace orthoflow::simulation {

/// @brief Timing of the simulated host for arms. Plain data with defaults.
struct SimJacoTransportConfig {
  std::chrono::nanoseconds transfer_latency{1'000'000};  ///< every interrupt transfer takes this
  std::chrono::milliseconds infinite_wait{5'000};  ///< an IN with timeout 0 and no reply waits this
  std::uint8_t first_address = 2;  ///< addresses are handed out from here, per bus, never reused
};

/// @brief The simulated host with arms numbered from 0 in the order added.
/// @note Not thread-safe (one USB thread).
class SimJacoTransport final : public SimUsbHost {
 public:
  /// @brief A transport with its own ManualClock starting at 0. @pre none.
  explicit SimJacoTransport(SimJacoTransportConfig config = {});
  /// @brief A transport moving @p clock. @pre @p clock outlives the transport.
  explicit SimJacoTransport(drivers::ManualClock& clock, SimJacoTransportConfig config = {});

  /// @brief Plugs in (and powers on) an arm now; returns its index. @pre Its bus has addresses
  /// left. @note Allocates (call at test set-up).
  std::size_t add_arm(SimJacoConfig config);
  /// @brief The device model of arm @p index (ground truth, faults). @pre index < arm_count().
  [[nodiscard]] SimJacoArm& arm(std::size_t index);
  /// @brief Arms added. @pre none.
  [[nodiscard]] std::size_t arm_count() const noexcept { return arms_.size(); }
  /// @brief False between an unplug and the replug. @pre index < arm_count().
  [[nodiscard]] bool present(std::size_t index) const;
  /// @brief Pulls arm @p index's cable now. No-op if absent. @pre index < arm_count().
  void unplug(std::size_t index);
  /// @brief Plugs it back now at a new address. No-op if present. @pre index < arm_count().
  void replug(std::size_t index);

 private:
  struct Arm {
    std::size_t device = 0;  // index on the host
    SimJacoArm* model = nullptr;
  };
  [[nodiscard]] const Arm& at(std::size_t index, const char* operation) const;

  std::vector<Arm> arms_;
};

}  // namespace orthoflow::simulation
