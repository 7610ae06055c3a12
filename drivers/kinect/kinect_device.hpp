#pragma once
/// @file
/// @brief KinectDevice: a KinectCamera on its own USB thread. The thread owns the transport and
/// the camera, pumps events, runs the watchdog and the reopen; consumers on other threads take the
/// newest depth frame (wait-free) and read the health counters.
///
/// Simulated time: with `pace_to_wall_clock`, the thread keeps the transport's clock (a
/// simulator's) no faster than wall time, so a simulated camera delivers 30 frames per real second
/// as a real one does. Without it a simulator runs as fast as the CPU allows (tests).
#include <atomic>
#include <memory>
#include <thread>

#include "core/result.hpp"
#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

/// @brief How the USB thread runs.
struct DeviceOptions {
  CameraOptions camera{};
  UsbTimeout pump_timeout{5};       ///< longest wait in one handle_events()
  bool pace_to_wall_clock = false;  ///< for simulated transports (see the file comment)
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
  /// @brief Pump errors seen by the thread (each also counted by the camera). @pre none.
  [[nodiscard]] std::uint64_t pump_errors() const noexcept {
    return pump_errors_.load(std::memory_order_relaxed);
  }

 private:
  KinectDevice() = default;
  void run() noexcept;

  DeviceOptions options_{};
  std::unique_ptr<UsbTransport> transport_;
  std::unique_ptr<KinectCamera> camera_;
  Calibration calibration_{};
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> pump_errors_{0};
  std::thread thread_;
};

}  // namespace orthoflow::drivers::kinect
