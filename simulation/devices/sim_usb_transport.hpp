#pragma once
/// @file
/// @brief SimUsbTransport: the simulated USB host (sim_usb_host.hpp) set up for simulated Kinects
/// (sim_kinect_usb_device.hpp), with Kinect-numbered accessors, so the Kinect driver runs end to
/// end on a machine without USB (specs/USB_TESTING.md 3.3). Every rule of the host applies:
/// time (handle_events stops at the next iso completion or fault time; control and bulk take
/// control_latency, a stalled one its whole timeout), iso streams (back-to-back transfers,
/// zero-length idle microframes, OVERFLOW, NO_DEVICE on unplug, CANCELLED on an unrequested
/// cancel), and the strict checks. Those of the Kinect (sim_kinect_usb_device.hpp):
/// - only interface 0 exists; alternate settings: 0, plus 1 on the K4W camera, which streams in 1;
/// - claim_interface is BUSY while the camera's kernel driver (gspca_kinect, bound at plug-in:
///   kernel_driver_active() is true) is attached;
/// - bulk: only the audio function's 0x01 / 0x81 on a claimed interface; interrupt: NOT_FOUND;
/// - the audio function re-enumerates on its own after a firmware execute (sim_kinect_device.hpp):
///   while away it is not enumerated and its handles answer NO_DEVICE; it comes back at a new
///   address (handed out when first seen by enumerate / open);
/// - a handle of a Kinect that was unplugged answers NO_DEVICE, even after the Kinect is back.
/// make_sim_kinect_host() builds the one simulated camera `orthoflow kinect --sim` and the
/// kinect_source graph node (`device: sim`) run on.
/// Threading: one thread, like every UsbTransport. Determinism: same calls, same bytes and times.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drivers/usb/monotonic_clock.hpp"
#include "simulation/devices/sim_kinect_device.hpp"
#include "simulation/devices/sim_usb_host.hpp"

namespace orthoflow::simulation {

/// @brief Timing of the simulated host for Kinects. Plain data with defaults.
struct SimUsbTransportConfig {
  std::chrono::nanoseconds control_latency{50'000};  ///< every control transfer takes this long
  std::chrono::milliseconds infinite_wait{
      5'000};                      ///< a stall with timeout 0 waits this, then TIMEOUT
  std::uint8_t first_address = 2;  ///< addresses are handed out from here, per bus, never reused
};

/// @brief The simulated host with Kinects numbered from 0 in the order added.
/// @note Not thread-safe (one USB thread).
class SimUsbTransport final : public SimUsbHost {
 public:
  /// @brief A transport with its own ManualClock starting at 0. @pre none.
  explicit SimUsbTransport(SimUsbTransportConfig config = {});
  /// @brief A transport moving @p clock. @pre @p clock outlives the transport.
  explicit SimUsbTransport(drivers::ManualClock& clock, SimUsbTransportConfig config = {});

  /// @brief Plugs in a Kinect now; returns its index. Its fault times apply from now on.
  /// @pre Its bus has addresses left. @note Allocates (call at test set-up).
  std::size_t add_kinect(SimKinectConfig config);
  /// @brief The device model of Kinect @p index (registers, raw frames, motor, faults).
  /// @pre index < kinect_count().
  [[nodiscard]] SimKinectDevice& kinect(std::size_t index);
  /// @brief Kinects added. @pre none.
  [[nodiscard]] std::size_t kinect_count() const noexcept { return kinects_.size(); }
  /// @brief False between an unplug and the replug. @pre index < kinect_count().
  [[nodiscard]] bool present(std::size_t index) const;
  /// @brief Unplugs Kinect @p index now (as faults.disconnect_at_ns would). No-op if absent.
  /// @pre index < kinect_count().
  void unplug(std::size_t index);
  /// @brief Plugs it back now at new addresses, in power-on state. No-op if present.
  /// @pre index < kinect_count().
  void replug(std::size_t index);

 private:
  struct Kinect {
    std::size_t device = 0;  // index on the host
    SimKinectDevice* model = nullptr;
  };
  [[nodiscard]] const Kinect& at(std::size_t index, const char* operation) const;

  std::vector<Kinect> kinects_;
};

/// @brief The simulated camera of the CLI and of the graph node. Plain data with defaults.
struct SimKinectHostOptions {
  KinectModel model = KinectModel::K1414;
  std::uint64_t scene_seed = 42;  ///< the default tabletop scene's seed
  double drop_rate = 0.0;         ///< iso packets dropped on the bus, per packet
  std::string serial{};           ///< empty: SimKinectConfig's default
};

/// @brief A fresh host with one Kinect as @p options say (its clock at 0, the head level).
/// @pre drop_rate in [0, 1]. @note Allocates; the Kinect renders its scene on first use.
[[nodiscard]] std::unique_ptr<SimUsbTransport> make_sim_kinect_host(
    const SimKinectHostOptions& options = {});

}  // namespace orthoflow::simulation
