// Hardware tests of the Kinect driver: they run only with KINECT_HW=1 on a machine with a Kinect v1
// plugged in, and report SKIPPED (not passed) everywhere else, CI included (USB_TESTING.md 3.7).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string_view>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/usb/libusb_transport.hpp"

namespace orthoflow::drivers::kinect {
namespace {

using namespace std::chrono_literals;

bool hardware_requested() {
  const char* v = std::getenv("KINECT_HW");
  return v != nullptr && std::string_view(v) == "1";
}

TEST(KinectHardware, StreamsThirtyPlausibleFramesFromARealCamera) {
  if (!hardware_requested()) GTEST_SKIP() << "set KINECT_HW=1 with a Kinect v1 plugged in";
  auto usb = LibusbTransport::create();
  ASSERT_TRUE(usb.has_value()) << to_string(usb.error());
  auto camera = KinectCamera::open(*usb.value());
  ASSERT_TRUE(camera.has_value()) << to_string(camera.error());
  KinectCamera& cam = *camera.value();
  const Calibration& cal = cam.calibration();
  EXPECT_GT(cal.zero_plane.reference_pixel_size_mm, 0.09F);
  EXPECT_LT(cal.zero_plane.reference_pixel_size_mm, 0.12F);
  EXPECT_GT(cal.const_shift, 100);
  ASSERT_TRUE(cam.start_depth().has_value());
  std::size_t frames = 0, with_depth = 0;
  std::uint64_t first_ticks = 0, last_ticks = 0;
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (frames < 30 && std::chrono::steady_clock::now() < until) {
    (void)cam.pump(10ms);
    if (const DepthFrame* f = cam.latest_depth()) {
      if (frames == 0) first_ticks = f->device_ticks;
      last_ticks = f->device_ticks;
      std::size_t valid = 0;
      for (const std::uint16_t r : f->raw) valid += r < RAW_NO_READING ? 1U : 0U;
      with_depth += valid > DEPTH_PIXELS / 4 ? 1U : 0U;
      ++frames;
    }
  }
  ASSERT_TRUE(cam.stop_depth().has_value());
  EXPECT_EQ(frames, 30U);
  EXPECT_GE(with_depth, 25U) << "most frames should see something within range";
  // 30 Hz on the device clock: 29 frame periods of 2,000,000 ticks, within 5 %.
  EXPECT_NEAR(static_cast<double>(last_ticks - first_ticks), 29 * 2e6, 29 * 2e6 * 0.05);
  const CameraHealth h = cam.health();
  std::printf("hardware: %llu frames, %llu degraded, lost packets %llu, resyncs %llu\n",
              static_cast<unsigned long long>(h.frames_delivered),
              static_cast<unsigned long long>(h.frames_degraded),
              static_cast<unsigned long long>(h.depth.lost_packets),
              static_cast<unsigned long long>(h.depth.resyncs));
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
