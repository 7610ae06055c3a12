#include "graphs/nodes/kinect_source.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/kinect/kinect_device.hpp"
#include "drivers/usb/libusb_transport.hpp"
#include "graphs/nodes/frame_source.hpp"
#include "graphs/nodes/node_support.hpp"
#include "kernels/depth_projection.hpp"
#include "simulation/devices/sim_usb_transport.hpp"

namespace orthoflow::graphs {

namespace {

using engine::Message;
using engine::ParamMap;
namespace kinect = drivers::kinect;

/// Frames of a Kinect v1 camera (real, over libusb, or the simulated one on simulated time paced to
/// the wall clock). produce() takes the newest depth frame the USB thread published, waiting at
/// most `wait_ms` for one (a bounded wait: no frame in time is a skipped frame, which the engine
/// counts as a source drop), and back-projects it into the block with the device's calibration.
class KinectSource final : public FrameSource {
 public:
  KinectSource(std::size_t capacity, const engine::NodeContext& context,
               std::unique_ptr<kinect::KinectDevice> device, std::chrono::milliseconds wait)
      : FrameSource(capacity, context), device_(std::move(device)), wait_(wait) {
    kinect::make_depth_table_m(device_->calibration(), table_m_);
    camera_ = kinect::depth_camera(device_->calibration());
    cloud_.resize(kinect::DEPTH_WIDTH, kinect::DEPTH_HEIGHT);
  }
  std::size_t device_counters(std::span<engine::DeviceCounter> out) const noexcept override {
    // The driver's own account (KinectCamera::health(), a spin-locked snapshot).
    const auto all = kinect::health_counters(device_->health());
    const std::size_t k = std::min(out.size(), all.size());
    for (std::size_t i = 0; i < k; ++i) out[i] = {all[i].name, all[i].value};
    return k;
  }
  engine::SourceStatus produce(Message& out) noexcept override {
    const kinect::DepthFrame* frame = device_->latest_depth();
    const auto deadline = std::chrono::steady_clock::now() + wait_;
    while (frame == nullptr && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::microseconds(500));
      frame = device_->latest_depth();
    }
    if (frame == nullptr) {
      out.skipped = true;  // the camera gave nothing in time: a source drop, not a hang
      return engine::SourceStatus::FRAME;
    }
    if (!take_block(out)) return engine::SourceStatus::FRAME;
    (void)kernels::depth_to_points(frame->raw, kinect::DEPTH_WIDTH, kinect::DEPTH_HEIGHT, table_m_,
                                   camera_, cloud_.points());
    cloud_.info.frame_id = frames_++;
    // 60 MHz ticks to ns: x 50 / 3, exact in integers.
    cloud_.info.sensor_stamp_ns = static_cast<std::int64_t>(frame->device_ticks * 50 / 3);
    // Stamped with its arrival (the last packet's), not the time the graph took it.
    cloud_.info.host_stamp_ns = device_->steady_ns_of(frame->host_ns);
    const auto gravity = device_->gravity();  // the USB thread's latest accelerometer reading
    cloud_.info.up = gravity ? gravity->up : std::array<float, 3>{};
    cloud_.info.up_age_ms = gravity ? gravity->age_ms : 0;
    emit_cloud(out, cloud_);
    return engine::SourceStatus::FRAME;
  }

 private:
  std::unique_ptr<kinect::KinectDevice> device_;
  std::chrono::milliseconds wait_;
  std::array<float, kernels::DISPARITY_TABLE_SIZE> table_m_{};
  kernels::DepthCamera camera_{};
  kernels::PointCloud cloud_;
  std::uint64_t frames_ = 0;
};

NodeResult make_kinect(const ParamMap& params, const engine::NodeContext& context) {
  auto capacity = frame_capacity(context);
  if (!capacity) return err(capacity.error());
  if (auto ok = params.only({"device", "serial", "wait_ms", "sim_seed", "sim_drop_rate"}); !ok)
    return err(ok.error());
  std::string device_kind, serial, e;
  std::int64_t wait_ms = 100, sim_seed = 42;
  double drop_rate = 0.0;
  take(params.text("device", "usb"), device_kind, e);
  take(params.text("serial", ""), serial, e);
  take(params.integer("wait_ms", 100, 1, 10'000), wait_ms, e);
  take(params.integer("sim_seed", 42, 0, INT64_MAX), sim_seed, e);
  take(params.number("sim_drop_rate", 0.0, 0.0, 0.5), drop_rate, e);
  if (!e.empty()) return err(e);
  if (*capacity < kinect::DEPTH_PIXELS)
    return err(full_frame_too_large("kinect_source", *capacity, context));
  kinect::DeviceOptions options;
  options.camera.serial = serial;
  std::unique_ptr<drivers::UsbTransport> transport;
  if (device_kind == "sim") {
    simulation::SimKinectHostOptions sim;
    sim.scene_seed = static_cast<std::uint64_t>(sim_seed);
    sim.drop_rate = drop_rate;
    sim.serial = serial;
    transport = simulation::make_sim_kinect_host(sim);
    options.pace_to_wall_clock = true;
  } else if (device_kind == "usb") {
    auto usb = drivers::LibusbTransport::create();
    if (!usb.has_value())
      return err("kinect_source: cannot start libusb: " + drivers::to_string(usb.error()));
    transport = std::move(usb.value());
  } else {
    return err("kinect_source: device must be usb or sim, not '" + device_kind + "'");
  }
  auto device = kinect::KinectDevice::start(std::move(transport), options);
  if (!device.has_value()) {
    const auto& why = device.error();
    if (why.code == kinect::KinectError::Code::NO_CAMERA)
      return err(serial.empty() ? std::string("kinect_source: no Kinect v1 camera found (lsusb "
                                              "should list 045e:02ae or 045e:02bf; is the udev "
                                              "rule from deploy/ installed?)")
                                : "kinect_source: no Kinect v1 camera with serial " + serial);
    return err("kinect_source: cannot start the camera: " + kinect::to_string(why));
  }
  if (!device.value()->no_accelerometer().empty())
    std::fprintf(stderr, "kinect_source: no accelerometer, frames carry no gravity: %s\n",
                 device.value()->no_accelerometer().c_str());
  return std::unique_ptr<engine::Node>(new KinectSource(
      *capacity, context, std::move(device.value()), std::chrono::milliseconds(wait_ms)));
}

}  // namespace

void add_kinect_source(engine::NodeRegistry& registry) {
  registry.add("kinect_source",
               "a Kinect v1 camera's depth: device=usb|sim, serial, wait_ms, sim_seed, "
               "sim_drop_rate",
               make_kinect);
}

}  // namespace orthoflow::graphs
