// The Kinect driver's cost per depth frame, on the packets the simulated camera sends (captured
// once through the USB seam): the frame assembler over 242 isochronous packets, the 11-bit unpack
// with hole masking (decode_depth, the camera's own frame step) and the back-projection into the
// organized cloud (kernels::depth_to_points, the kinect_source node's step). The SIMD kernels
// against their scalar twins in the same run, without loss and with 1 % of the packets lost.
// Share of one core at 30 Hz = time per frame x 30.
#include <benchmark/benchmark.h>

#include <vector>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_control.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "kernels/depth_projection.hpp"
#include "kernels/point_cloud.hpp"
#include "simulation/devices/sim_usb_transport.hpp"

namespace dk = orthoflow::drivers::kinect;
namespace ok = orthoflow::kernels;

namespace {

/// Two frames' worth of the simulated camera's depth packets, as the driver receives them.
std::vector<std::vector<std::uint8_t>> capture_packets() {
  orthoflow::simulation::SimUsbTransport usb;
  usb.add_kinect({});
  auto cameras = usb.enumerate(dk::VENDOR_MICROSOFT, dk::PID_CAMERA);
  auto handle = usb.open(cameras.value().front());
  (void)usb.kernel_driver_active(handle.value(), 0);
  (void)usb.detach_kernel_driver(handle.value(), 0);
  (void)usb.claim_interface(handle.value(), 0);
  std::vector<std::vector<std::uint8_t>> packets;
  std::size_t eofs = 0;
  (void)usb.start_iso(handle.value(), dk::EP_DEPTH, {},
                      [&](std::span<const std::byte> b, std::size_t, auto) {
                        if (b.empty() || eofs >= 3) return;
                        const auto* p = reinterpret_cast<const std::uint8_t*>(b.data());
                        if (eofs >= 1) packets.emplace_back(p, p + b.size());  // whole frames only
                        if (b.size() > 3 && (p[3] & 0x0F) == 5) ++eofs;
                      });
  dk::KinectControl control(usb, handle.value());
  (void)control.run(dk::depth_start_script(dk::DepthFormat::BITS_11));
  while (eofs < 3) (void)usb.handle_events(std::chrono::milliseconds(5));
  return packets;
}

const std::vector<std::vector<std::uint8_t>>& packets() {
  static const auto captured = capture_packets();
  return captured;
}

void BM_KinectDepthFrame(benchmark::State& state) {
  const bool scalar = state.range(0) == 0;
  const auto loss_permille = static_cast<std::size_t>(state.range(1));
  const auto& stream = packets();
  dk::Calibration calibration;
  std::array<float, ok::DISPARITY_TABLE_SIZE> table{};
  dk::make_depth_table_m(calibration, table);
  const ok::DepthCamera camera = dk::depth_camera(calibration);
  std::vector<std::uint16_t> raw(dk::DEPTH_PIXELS);
  ok::PointCloud cloud;
  cloud.resize(dk::DEPTH_WIDTH, dk::DEPTH_HEIGHT);
  const auto geometry = dk::depth_geometry(11);
  std::size_t valid = 0, frames = 0, degraded = 0;
  dk::FrameAssembler assembler(geometry, [&](const dk::AssembledFrame& f) {
    dk::decode_depth(f, geometry, dk::DepthFormat::BITS_11, raw, scalar);
    valid += scalar ? ok::depth_to_points_scalar(raw, dk::DEPTH_WIDTH, dk::DEPTH_HEIGHT, table,
                                                 camera, cloud.points())
                    : ok::depth_to_points(raw, dk::DEPTH_WIDTH, dk::DEPTH_HEIGHT, table, camera,
                                          cloud.points());
    ++frames;
    degraded += f.complete ? 0U : 1U;
  });
  std::size_t k = 0;
  for (auto _ : state) {
    for (const auto& p : stream) {
      ++k;
      if (loss_permille > 0 && (k * 7919) % 1000 < loss_permille) continue;  // spread, repeatable
      assembler.push(p, 0);
    }
    benchmark::DoNotOptimize(cloud.points().z.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(frames));  // items/s = depth frames/s
  state.counters["degraded_%"] =
      frames > 0 ? 100.0 * static_cast<double>(degraded) / static_cast<double>(frames) : 0.0;
  state.counters["valid_pts"] = frames > 0 ? static_cast<double>(valid / frames) : 0.0;
  state.SetLabel(scalar ? "scalar" : "simd");
}

}  // namespace

BENCHMARK(BM_KinectDepthFrame)
    ->ArgsProduct({{0, 1}, {0, 10}})
    ->ArgNames({"simd", "loss_permille"})
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
