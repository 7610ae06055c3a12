#include "drivers/kinect/kinect_device.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>

#include "drivers/kinect/kinect_gravity.hpp"

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
  if (options.accel_period.count() > 0) {
    // The motor function is a sibling device on the same transport, driven from the USB thread.
    auto motor = KinectMotor::open(*device->transport_, device->camera_->info());
    if (motor.has_value()) {
      device->motor_ = std::move(motor.value());
    } else {
      device->no_accel_ = to_string(motor.error());
    }
  } else {
    device->no_accel_ = "accelerometer reads are off (accel_period 0)";
  }
  device->steady_minus_transport_ns_ = std::chrono::steady_clock::now().time_since_epoch().count() -
                                       device->transport_->clock().now_ns();
  KinectDevice* self = device.get();
  device->thread_ = std::thread([self] { self->run(); });
  return device;
}

KinectDevice::~KinectDevice() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (camera_) (void)camera_->stop_depth();
  motor_.reset();
  camera_.reset();  // closes the device before its transport goes
}

void KinectDevice::read_accelerometer() noexcept {
  const auto now = std::chrono::steady_clock::now();
  if (motor_ == nullptr || now < next_accel_) return;
  next_accel_ = now + options_.accel_period;
  auto state = motor_->read_state();  // one control transfer on this thread
  if (state.has_value()) {
    std::uint64_t raw = 0;
    for (int k = 0; k < 3; ++k)
      raw |= std::uint64_t{static_cast<std::uint16_t>(state->accel_counts[k])} << (16 * k);
    raw |= std::uint64_t{static_cast<std::uint8_t>(state->tilt_raw)} << 48;
    raw |= std::uint64_t{state->status_raw} << 56;
    raw_packed_.store(raw, std::memory_order_relaxed);
    raw_sequence_.fetch_add(1, std::memory_order_release);
  }
  const auto up = state.has_value() ? up_from_accel(state->accel_counts[0], state->accel_counts[1],
                                                    state->accel_counts[2])
                                    : std::nullopt;
  if (!up) {
    accel_failures_.fetch_add(1, std::memory_order_relaxed);
    up_packed_.store(0, std::memory_order_release);  // the last reading is no longer current
    return;
  }
  std::uint64_t packed = 1;  // bit 0..15: valid
  for (int k = 0; k < 3; ++k) {
    const auto q =
        static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround((*up)[k] * 32767.0F)));
    packed |= std::uint64_t{q} << (16 * (k + 1));
  }
  up_read_ns_.store(now.time_since_epoch().count(), std::memory_order_relaxed);
  up_packed_.store(packed, std::memory_order_release);
}

std::int64_t KinectDevice::steady_ns_of(std::int64_t transport_ns) const noexcept {
  const std::int64_t now = std::chrono::steady_clock::now().time_since_epoch().count();
  return std::min(now, transport_ns + steady_minus_transport_ns_);
}

RawTiltReading KinectDevice::raw_tilt() const noexcept {
  RawTiltReading r;
  r.sequence = raw_sequence_.load(std::memory_order_acquire);
  const std::uint64_t raw = raw_packed_.load(std::memory_order_relaxed);
  for (int k = 0; k < 3; ++k) r.accel_counts[k] = static_cast<std::int16_t>(raw >> (16 * k));
  r.tilt_raw = static_cast<std::int8_t>(static_cast<std::uint8_t>(raw >> 48));
  r.status_raw = static_cast<std::uint8_t>(raw >> 56);
  return r;
}

std::optional<GravityReading> KinectDevice::gravity() const noexcept {
  const std::uint64_t packed = up_packed_.load(std::memory_order_acquire);
  if ((packed & 0xFFFFU) == 0) return std::nullopt;
  GravityReading g;
  for (int k = 0; k < 3; ++k)
    g.up[k] = static_cast<float>(static_cast<std::int16_t>(packed >> (16 * (k + 1)))) / 32767.0F;
  const std::int64_t age_ns = std::chrono::steady_clock::now().time_since_epoch().count() -
                              up_read_ns_.load(std::memory_order_relaxed);
  g.age_ms = static_cast<std::uint32_t>(std::clamp<std::int64_t>(age_ns / 1'000'000, 0, INT32_MAX));
  return g;
}

void KinectDevice::run() noexcept {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::int64_t clock_start = transport_->clock().now_ns();
  while (!stop_.load(std::memory_order_acquire)) {
    if (!camera_->pump(options_.pump_timeout).has_value()) {
      pump_errors_.fetch_add(1, std::memory_order_relaxed);
    }
    read_accelerometer();
    if (options_.pace_to_wall_clock) {
      const auto ahead = std::chrono::nanoseconds(transport_->clock().now_ns() - clock_start);
      std::this_thread::sleep_until(wall_start + ahead);
    }
  }
}

}  // namespace orthoflow::drivers::kinect
