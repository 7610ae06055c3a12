// SimKinectDevice: the 1414 motor (KINECT_V1.md 11), the registers that start and stop the
// streams (KINECT_V1.md 5), the iso packets, the frame sources and the default scene.
#include <algorithm>
#include <cmath>

#include "core/assert.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "kernels/point_cloud.hpp"
#include "simulation/devices/sim_kinect_device.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::simulation {

namespace {

constexpr std::size_t PIXELS = std::size_t{KINECT_FRAME_WIDTH} * KINECT_FRAME_HEIGHT;
constexpr std::size_t IR_PIXELS = std::size_t{KINECT_FRAME_WIDTH} * KINECT_IR_HEIGHT;
constexpr double MOTOR_LIMIT_DEG = 31.0;
constexpr double ACCEL_COUNTS_PER_G = 819.0;  // Kionix KXSD9
constexpr std::uint8_t TILT_STOPPED = 0x00;
constexpr std::uint8_t TILT_AT_LIMIT = 0x01;
constexpr std::uint8_t TILT_MOVING = 0x04;
constexpr std::uint16_t REG_VIDEO_MODE = 0x05;
constexpr std::uint16_t REG_DEPTH_MODE = 0x06;
constexpr std::uint16_t REG_COLOR_FORMAT = 0x0C;
constexpr std::uint16_t REG_DEPTH_FORMAT = 0x12;

std::int64_t microframe_after(std::int64_t now_ns) noexcept {
  return now_ns / USB_MICROFRAME_NS + 1;
}

void put_be16(std::span<std::byte> out, std::size_t at, std::int16_t v) noexcept {
  const auto u = static_cast<std::uint16_t>(v);
  out[at] = std::byte{static_cast<std::uint8_t>(u >> 8)};
  out[at + 1] = std::byte{static_cast<std::uint8_t>(u & 0xFFU)};
}

}  // namespace

double SimKinectDevice::tilt_deg(std::int64_t now_ns) noexcept {
  if (now_ns > motor_.updated_ns) {
    const double step =
        config_.motor_slew_deg_per_s * static_cast<double>(now_ns - motor_.updated_ns) * 1e-9;
    const double gap = motor_.target_deg - motor_.angle_deg;
    motor_.angle_deg =
        std::abs(gap) <= step ? motor_.target_deg : motor_.angle_deg + std::copysign(step, gap);
    motor_.updated_ns = now_ns;
  }
  return motor_.angle_deg;
}

double SimKinectDevice::mount_pitch_deg() noexcept {
  if (!mount_pitch_) {
    mount_pitch_ = config_.mount_pitch_deg ? *config_.mount_pitch_deg
                   : config_.depth_source
                       ? 0.0
                       : -make_scene(SceneConfig{}, config_.scene_seed).table.tilt_rad * 180.0 /
                             3.14159265358979323846;
  }
  return *mount_pitch_;
}

SimControlReply SimKinectDevice::motor_control(const drivers::UsbControlSetup& setup,
                                               std::span<std::byte> data,
                                               std::int64_t now_ns) noexcept {
  const double angle = tilt_deg(now_ns);
  if (setup.request_type == 0x40 && setup.request == 0x31) {  // set tilt: 2 x degrees, signed
    const double wanted = static_cast<std::int16_t>(setup.value) / 2.0;
    motor_.target_deg = std::clamp(wanted, -MOTOR_LIMIT_DEG, MOTOR_LIMIT_DEG);
    motor_.clamped = motor_.target_deg != wanted;
    return {SimControlOutcome::OK, data.size()};
  }
  if (setup.request_type == 0x40 && setup.request == 0x06) {  // LED
    if (setup.value > 6) return {SimControlOutcome::PIPE, 0};
    motor_.led = static_cast<std::uint8_t>(setup.value);
    return {SimControlOutcome::OK, data.size()};
  }
  if (setup.request_type == 0xC0 && setup.request == 0x10 && !data.empty()) {  // readiness
    data[0] = std::byte{0x22};
    return {SimControlOutcome::OK, 1};
  }
  if (setup.request_type == 0xC0 && setup.request == 0x32 && data.size() >= 10) {  // state
    // Gravity in the camera frame when the head is pitched by the mount plus `angle` (no roll): Y
    // up at level. The tilt byte reports the motor angle alone.
    const double rad = (angle + mount_pitch_deg()) * 3.14159265358979323846 / 180.0;
    std::fill(data.begin(), data.begin() + 10, std::byte{0});
    put_be16(data, 2, 0);
    put_be16(data, 4, static_cast<std::int16_t>(std::lround(ACCEL_COUNTS_PER_G * std::cos(rad))));
    put_be16(data, 6, static_cast<std::int16_t>(std::lround(ACCEL_COUNTS_PER_G * std::sin(rad))));
    data[8] =
        std::byte{static_cast<std::uint8_t>(static_cast<std::int8_t>(std::lround(angle * 2)))};
    const std::uint8_t status = angle != motor_.target_deg ? TILT_MOVING
                                : motor_.clamped           ? TILT_AT_LIMIT
                                                           : TILT_STOPPED;
    data[9] = std::byte{status};
    return {SimControlOutcome::OK, 10};
  }
  return {SimControlOutcome::PIPE, 0};
}

void SimKinectDevice::ensure_default_scene() {
  if (!scene_raw_.empty()) return;
  const Scene scene = make_scene(SceneConfig{}, config_.scene_seed);
  RenderOptions options;
  options.depth = config_.depth;
  core::Rng rng(config_.scene_seed ^ 0x5EEDULL);
  kernels::PointCloud cloud;
  render_scene(scene, options, rng, cloud);
  OF_ENFORCE(cloud.size() == PIXELS, "SimKinectDevice: the scene is not 640x480");
  scene_raw_.assign(PIXELS, KINECT_NO_READING);
  scene_bayer_.assign(PIXELS, 0);
  scene_ir_.assign(IR_PIXELS, 0);
  const drivers::kinect::DisparityModel model = disparity_model(config_.depth);
  const auto z = cloud.z();
  const auto rgb = cloud.rgb();
  for (std::size_t i = 0; i < PIXELS; ++i) {
    const std::size_t row = i / KINECT_FRAME_WIDTH;
    const std::size_t col = i % KINECT_FRAME_WIDTH;
    // GRBG: G R on even rows, B G on odd rows (KINECT_V1.md 7.3).
    const unsigned shift = (row % 2 == 0) == (col % 2 == 0) ? 8U : ((row % 2 == 0) ? 16U : 0U);
    scene_bayer_[i] = rgb.empty() ? std::uint8_t{0} : static_cast<std::uint8_t>(rgb[i] >> shift);
    if (!std::isfinite(z[i]) || z[i] <= 0.0F) continue;
    scene_raw_[i] = drivers::kinect::mm_to_raw(static_cast<double>(z[i]) * 1000.0, model);
    const double intensity = 300.0 / (static_cast<double>(z[i]) * static_cast<double>(z[i]));
    scene_ir_[i] = static_cast<std::uint16_t>(std::min(intensity, 1023.0));
  }
}

void SimKinectDevice::depth_raw_image(std::uint64_t frame, std::span<std::uint16_t> raw) {
  OF_ENFORCE(raw.size() == PIXELS, "depth_raw_image: needs 640 x 480 values");
  if (config_.depth_source) {
    config_.depth_source(frame, raw);
    return;
  }
  ensure_default_scene();
  std::copy(scene_raw_.begin(), scene_raw_.end(), raw.begin());
}

void SimKinectDevice::bayer_image(std::uint64_t frame, std::span<std::uint8_t> bayer) {
  OF_ENFORCE(bayer.size() == PIXELS, "bayer_image: needs 640 x 480 values");
  if (config_.bayer_source) {
    config_.bayer_source(frame, bayer);
    return;
  }
  ensure_default_scene();
  std::copy(scene_bayer_.begin(), scene_bayer_.end(), bayer.begin());
}

void SimKinectDevice::ir_image(std::uint64_t frame, std::span<std::uint16_t> ir) {
  OF_ENFORCE(ir.size() == IR_PIXELS, "ir_image: needs 640 x 488 values");
  if (config_.ir_source) {
    config_.ir_source(frame, ir);
    return;
  }
  ensure_default_scene();
  std::copy(scene_ir_.begin(), scene_ir_.end(), ir.begin());
}

void SimKinectDevice::fill_frame(SimStreamMode mode, std::uint64_t frame,
                                 std::span<std::uint8_t> packed) {
  const std::span<std::uint16_t> pixels(scratch16_.data(), PIXELS);
  switch (mode) {
    case SimStreamMode::DEPTH_11BIT:
      depth_raw_image(frame, pixels);
      sim_pack_msb_first(pixels, 11, packed);
      break;
    case SimStreamMode::DEPTH_10BIT:
      depth_raw_image(frame, pixels);
      for (std::uint16_t& v : pixels) v = std::min<std::uint16_t>(v, 1023);
      sim_pack_msb_first(pixels, 10, packed);
      break;
    case SimStreamMode::BAYER:
      bayer_image(frame, packed.first(PIXELS));
      break;
    case SimStreamMode::IR_10BIT:
      ir_image(frame, std::span<std::uint16_t>(scratch16_));
      sim_pack_msb_first(scratch16_, 10, packed);
      break;
    case SimStreamMode::OFF:
      break;
  }
}

void SimKinectDevice::write_register(std::uint16_t address, std::uint16_t value,
                                     std::int64_t now_ns) noexcept {
  registers_[address] = value;
  writes_.emplace_back(address, value);
  const std::int64_t mf = microframe_after(now_ns);
  if (address == REG_DEPTH_MODE) {
    const std::uint16_t format = reg(REG_DEPTH_FORMAT).value_or(0);
    const SimStreamMode mode = format == 3   ? SimStreamMode::DEPTH_11BIT
                               : format == 2 ? SimStreamMode::DEPTH_10BIT
                                             : SimStreamMode::OFF;
    if (value == 2 && mode != SimStreamMode::OFF) {
      if (!config_.depth_source) ensure_default_scene();
      depth_.start(mode, mf);
    } else {
      depth_.stop(mf);
    }
  } else if (address == REG_VIDEO_MODE) {
    // UYVY (reg 0x0C = 5) is not simulated: such a start sends nothing.
    const bool bayer = value == 1 && reg(REG_COLOR_FORMAT).value_or(0) == 0;
    if (bayer || value == 3) {
      if (!config_.bayer_source || !config_.ir_source) ensure_default_scene();
      video_.start(bayer ? SimStreamMode::BAYER : SimStreamMode::IR_10BIT, mf);
    } else {
      video_.stop(mf);
    }
  }
}

std::size_t SimKinectDevice::iso_packet(std::uint8_t endpoint, std::int64_t microframe,
                                        std::span<std::byte> out) noexcept {
  if (endpoint == KINECT_DEPTH_ENDPOINT)
    return depth_.packet(microframe, faults_.packets, rng_, out);
  if (endpoint == KINECT_VIDEO_ENDPOINT)
    return video_.packet(microframe, faults_.packets, rng_, out);
  return 0;
}

}  // namespace orthoflow::simulation
