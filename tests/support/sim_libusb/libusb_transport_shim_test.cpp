// orthoflow's real libusb transport (drivers/usb/libusb_transport.hpp) end to end against the
// simulated Kinect, through the sim_libusb shim: the binary links the real libusb-1.0; CTest starts
// it with LD_LIBRARY_PATH=<the shim's directory> and ORTHOFLOW_SIM_KINECT_PACE=max, so the dynamic
// loader binds every libusb call to the shim. Frames are compared bit for bit with SimKinectDevice
// built from the same ORTHOFLOW_SIM_KINECT string.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <vector>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/usb/libusb_transport.hpp"
#include "simulation/devices/sim_kinect_device.hpp"
#include "tests/support/sim_libusb/sim_kinect_env.hpp"

namespace orthoflow::drivers::kinect {
namespace {

using namespace std::chrono_literals;
using simulation::SimKinectConfig;
using simulation::SimKinectDevice;

// Sets ORTHOFLOW_SIM_KINECT for the next libusb_init (the shim reads it when its bus is created,
// at the first libusb_init after the last libusb_exit), and restores it.
class SimKinectEnv {
 public:
  explicit SimKinectEnv(const char* value) {
    const char* old = std::getenv(sim_libusb::ENV_KINECT);
    if (old != nullptr) saved_ = old;
    had_ = old != nullptr;
    ::setenv(sim_libusb::ENV_KINECT, value, 1);
  }
  ~SimKinectEnv() {
    if (had_) {
      ::setenv(sim_libusb::ENV_KINECT, saved_.c_str(), 1);
    } else {
      ::unsetenv(sim_libusb::ENV_KINECT);
    }
  }
  SimKinectEnv(const SimKinectEnv&) = delete;
  SimKinectEnv& operator=(const SimKinectEnv&) = delete;

 private:
  std::string saved_;
  bool had_ = false;
};

std::vector<DepthFrame> collect(KinectCamera& camera, std::size_t frames) {
  std::vector<DepthFrame> out;
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < until && out.size() < frames) {
    (void)camera.pump(5ms);
    if (const DepthFrame* f = camera.latest_depth()) out.push_back(*f);
  }
  return out;
}

// Streams from the camera @p serial names (empty: the first) and checks frames and calibration.
void stream_and_compare(const SimKinectConfig& config, std::string_view serial) {
  auto transport_result = LibusbTransport::create();
  ASSERT_TRUE(transport_result.has_value()) << to_string(transport_result.error());
  LibusbTransport& usb = **transport_result;
  CameraOptions options;
  options.serial = serial;
  auto camera_result = KinectCamera::open(usb, options);
  ASSERT_TRUE(camera_result.has_value()) << to_string(camera_result.error());
  KinectCamera& camera = **camera_result;
  EXPECT_EQ(camera.info().serial.view(), config.serial);
  const Calibration& cal = camera.calibration();
  EXPECT_NEAR(cal.zero_plane.reference_pixel_size_mm, config.depth.ref_pix_mm, 1e-6);
  EXPECT_NEAR(cal.zero_plane.reference_distance_mm, config.depth.ref_dist_mm, 1e-4);
  EXPECT_NEAR(cal.zero_plane.dcmos_emitter_dist_cm, config.depth.emitter_dist_cm, 1e-5);
  EXPECT_FLOAT_EQ(cal.zero_plane.dcmos_rcmos_dist_cm, 2.4F);  // libfreenect's override
  EXPECT_NEAR(cal.reported_rcmos_dist_cm, config.calibration.dcmos_rcmos_dist_cm, 1e-6);
  EXPECT_EQ(cal.const_shift, static_cast<std::uint16_t>(config.depth.const_shift + 0.5));

  ASSERT_TRUE(camera.start_depth().has_value());
  const std::vector<DepthFrame> frames = collect(camera, 3);
  ASSERT_EQ(frames.size(), 3U);
  SimKinectDevice reference(config);
  std::vector<std::uint16_t> expected(DEPTH_PIXELS);
  for (const DepthFrame& f : frames) {
    EXPECT_TRUE(f.complete) << "frame " << f.number;
    reference.depth_raw_image(f.number, expected);
    EXPECT_TRUE(f.raw == expected) << "frame " << f.number << " differs from the simulator's";
  }
  EXPECT_NEAR(static_cast<double>(frames[2].device_ticks - frames[0].device_ticks) /
                  static_cast<double>(frames[2].number - frames[0].number),
              2e6, 2e4);
  ASSERT_TRUE(camera.stop_depth().has_value());
  const CameraHealth health = camera.health();
  EXPECT_EQ(health.iso_errors, 0U);
  EXPECT_EQ(health.frames_dropped, 0U);
}

TEST(SimLibusbTransport, TheLoaderBindsLibusbToTheShim) {
  void* symbol = ::dlsym(RTLD_DEFAULT, "libusb_init");
  ASSERT_NE(symbol, nullptr);
  Dl_info info{};
  ASSERT_NE(::dladdr(symbol, &info), 0);
  const std::string file = info.dli_fname;
  EXPECT_EQ(file.rfind(SIM_LIBUSB_DIR, 0), 0U)
      << "libusb_init comes from " << file << ": run this test through CTest (LD_LIBRARY_PATH)";
}

TEST(SimLibusbTransport, DefaultKinectStreamsTheSimulatorsFramesBitForBit) {
  SimKinectEnv env("");
  auto configs = sim_libusb::parse_kinects("");
  ASSERT_TRUE(configs.has_value());
  stream_and_compare(configs->at(0), "");
}

TEST(SimLibusbTransport, ListsTwoKinectsAndStreamsTheOneNamedBySerial) {
  const char* text = "model=1414,seed=7;model=1473,serial=B00367707227042B,depth=ramp";
  SimKinectEnv env(text);
  auto configs = sim_libusb::parse_kinects(text);
  ASSERT_TRUE(configs.has_value());
  {
    auto transport_result = LibusbTransport::create();
    ASSERT_TRUE(transport_result.has_value());
    auto cameras = list_cameras(**transport_result);
    ASSERT_TRUE(cameras.has_value()) << to_string(cameras.error());
    ASSERT_EQ(cameras->size(), 2U);
    EXPECT_EQ((*cameras)[0].model, Model::K1414);
    EXPECT_EQ((*cameras)[0].serial.view(), "A00364A11700045A");
    EXPECT_TRUE((*cameras)[0].has_motor);
    EXPECT_EQ((*cameras)[1].model, Model::K1473);
    EXPECT_EQ((*cameras)[1].serial.view(), "B00367707227042B");  // the audio sibling's
    EXPECT_FALSE((*cameras)[1].has_motor);
    EXPECT_EQ((*cameras)[0].usb.port_depth, 2);
    EXPECT_EQ((*cameras)[1].usb.ports()[0], 2);  // Kinect 1's hub defaults to root port 2
  }
  // The ramp is a different image every frame: frame numbers must line up, not only pixels.
  stream_and_compare(configs->at(1), "B00367707227042B");
}

TEST(SimLibusbTransport, AMalformedDescriptionFailsLibusbInit) {
  SimKinectEnv env("model=1515");
  auto transport_result = LibusbTransport::create();
  ASSERT_FALSE(transport_result.has_value());
  EXPECT_EQ(transport_result.error().code, UsbError::Code::INVALID_PARAM);
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
