#include "drivers/kinect/kinect_device.hpp"

#include <chrono>

namespace orthoflow::drivers::kinect {

Result<std::unique_ptr<KinectDevice>, KinectError> KinectDevice::start(
    std::unique_ptr<UsbTransport> transport, const DeviceOptions& options) {
  std::unique_ptr<KinectDevice> device(new KinectDevice());
  device->options_ = options;
  device->transport_ = std::move(transport);
  auto camera = KinectCamera::open(*device->transport_, options.camera);
  if (!camera.has_value()) return err(camera.error());
  device->camera_ = std::move(camera.value());
  if (auto ok = device->camera_->start_depth(); !ok.has_value()) return err(ok.error());
  device->calibration_ = device->camera_->calibration();
  KinectDevice* self = device.get();
  device->thread_ = std::thread([self] { self->run(); });
  return device;
}

KinectDevice::~KinectDevice() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (camera_) (void)camera_->stop_depth();
  camera_.reset();  // closes the device before its transport goes
}

void KinectDevice::run() noexcept {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::int64_t clock_start = transport_->clock().now_ns();
  while (!stop_.load(std::memory_order_acquire)) {
    if (!camera_->pump(options_.pump_timeout).has_value()) {
      pump_errors_.fetch_add(1, std::memory_order_relaxed);
    }
    if (options_.pace_to_wall_clock) {
      const auto ahead = std::chrono::nanoseconds(transport_->clock().now_ns() - clock_start);
      std::this_thread::sleep_until(wall_start + ahead);
    }
  }
}

}  // namespace orthoflow::drivers::kinect
