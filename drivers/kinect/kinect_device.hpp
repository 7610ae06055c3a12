#pragma once
/// @file
/// @brief KinectDevice: a KinectCamera on its own USB thread. The thread owns the transport and
/// the camera, pumps events, runs the watchdog and the reopen; consumers on other threads take the
/// newest depth frame (wait-free) and read the health counters.
///
/// Simulated time: with `pace_to_wall_clock`, the thread keeps the transport's clock (a
/// simulator's) no faster than wall time, so a simulated camera delivers 30 frames per real second
/// as a real one does. Without it a simulator runs as fast as the CPU allows (tests).
#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "core/result.hpp"
#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_motor.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

/// @brief How the USB thread runs.
struct DeviceOptions {
  CameraOptions camera{};
  UsbTimeout pump_timeout{5};       ///< longest wait in one handle_events()
  bool pace_to_wall_clock = false;  ///< for simulated transports (see the file comment)
  /// The USB thread reads the accelerometer (the motor function's state, KINECT_V1.md 11; a
  /// 1473 / K4W's through its running audio firmware) this often, beside the streams, so that each
  /// frame can carry where "up" is. 0, or a Kinect whose motor function does not open: none.
  std::chrono::milliseconds accel_period{100};
};

/// @brief The latest motor-state reading as the device sent it (what fakenect's `a-*.dump` holds).
struct RawTiltReading {
  std::array<std::int16_t, 3> accel_counts{};
  std::int8_t tilt_raw = 0;     ///< half degrees
  std::uint8_t status_raw = 0;  ///< 0 stopped, 1 at limit, 4 moving
  std::uint64_t sequence = 0;   ///< 1 for the first reading, +1 for each later one
};

/// @brief The latest accelerometer reading as "up" (kinect_gravity.hpp) and its age.
struct GravityReading {
  std::array<float, 3> up{};
  std::uint32_t age_ms = 0;
};

/// @brief A streaming camera on its own thread. Not copyable or movable.
class KinectDevice {
 public:
  /// @brief Opens the camera on @p transport (on the calling thread), starts depth and hands both
  /// to a new USB thread. @return the open or start error; nothing keeps running then.
  [[nodiscard]] static Result<std::unique_ptr<KinectDevice>, KinectError> start(
      std::unique_ptr<UsbTransport> transport, const DeviceOptions& options);
  /// @brief Stops the thread, then the stream, then closes the device. @pre none.
  ~KinectDevice();
  KinectDevice(const KinectDevice&) = delete;
  KinectDevice& operator=(const KinectDevice&) = delete;

  /// @brief The newest frame since the last call, or nullptr (one consumer thread). @note
  /// Wait-free.
  [[nodiscard]] const DepthFrame* latest_depth() noexcept { return camera_->latest_depth(); }
  /// @brief The counters (any thread).
  [[nodiscard]] CameraHealth health() const noexcept { return camera_->health(); }
  /// @brief The camera opened. @pre none.
  [[nodiscard]] const CameraInfo& info() const noexcept { return camera_->info(); }
  /// @brief Its calibration as read at the first open. @pre none.
  [[nodiscard]] const Calibration& calibration() const noexcept { return calibration_; }
  /// @brief The latest plausible accelerometer reading, or nullopt (none yet, no motor function,
  /// or the last reading was not a plausible gravity). Any thread; wait-free.
  [[nodiscard]] std::optional<GravityReading> gravity() const noexcept;
  /// @brief The latest motor state read (sequence 0: none yet). Any thread; wait-free.
  [[nodiscard]] RawTiltReading raw_tilt() const noexcept;
  /// @brief A time on the transport's clock (DepthFrame::host_ns: the last packet's arrival) on
  /// the host's steady clock: the offset measured at start (0 for libusb's steady clock; the
  /// pacing offset of a simulated transport), the result never later than now.
  [[nodiscard]] std::int64_t steady_ns_of(std::int64_t transport_ns) const noexcept;
  /// @brief Why the device reads no accelerometer (empty when it does). @pre none.
  [[nodiscard]] const std::string& no_accelerometer() const noexcept { return no_accel_; }
  /// @brief Accelerometer reads that failed or were not a plausible gravity. Any thread.
  [[nodiscard]] std::uint64_t accel_failures() const noexcept {
    return accel_failures_.load(std::memory_order_relaxed);
  }
  /// @brief Pump errors seen by the thread (each also counted by the camera). @pre none.
  [[nodiscard]] std::uint64_t pump_errors() const noexcept {
    return pump_errors_.load(std::memory_order_relaxed);
  }

 private:
  KinectDevice() = default;
  void run() noexcept;
  void read_accelerometer() noexcept;

  DeviceOptions options_{};
  std::unique_ptr<UsbTransport> transport_;
  std::unique_ptr<KinectCamera> camera_;
  Calibration calibration_{};
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> pump_errors_{0};
  std::unique_ptr<KinectMotor> motor_;  // the accelerometer; null: none (no_accel_ says why)
  std::string no_accel_;
  std::chrono::steady_clock::time_point next_accel_{};
  std::atomic<std::uint64_t> up_packed_{0};  // int16 x, y, z of the unit up, then 1 = valid
  std::atomic<std::int64_t> up_read_ns_{0};  // steady clock of that reading
  std::atomic<std::uint64_t> accel_failures_{0};
  std::atomic<std::uint64_t> raw_packed_{0};  // int16 x, y, z, then int8 tilt, uint8 status
  std::atomic<std::uint64_t> raw_sequence_{0};
  std::int64_t steady_minus_transport_ns_ = 0;  // measured once, at start
  std::thread thread_;
};

}  // namespace orthoflow::drivers::kinect
