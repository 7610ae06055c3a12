// The whole Kinect driver (discovery, control, calibration, iso streaming, assembly, unpacking,
// hole masking, watchdog, reopen) against the simulated Kinect of simulation/ on simulated time,
// through the USB seam. The simulator implements the documented protocol (KINECT_V1.md); it has
// never been compared with a real device, so these tests prove the driver against the brief.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/kinect/kinect_device.hpp"
#include "simulation/devices/sim_usb_transport.hpp"
#include "tests/support/counting_new.hpp"

namespace orthoflow::drivers::kinect {
namespace {

using simulation::KinectModel;
using simulation::SimKinectConfig;
using simulation::SimUsbTransport;
using namespace std::chrono_literals;

SimKinectConfig kinect_config(KinectModel model = KinectModel::K1414) {
  SimKinectConfig c;
  c.model = model;
  return c;
}

/// Pumps until @p frames frames were published (or @p budget of simulated time ran out), taking
/// each. (handle_events returns at each transfer completion: every 2 ms of simulated time.)
std::vector<DepthFrame> collect(SimUsbTransport& usb, KinectCamera& camera, std::size_t frames,
                                std::chrono::milliseconds budget = 2000ms) {
  std::vector<DepthFrame> out;
  const std::int64_t until = usb.clock().now_ns() + budget.count() * 1'000'000;
  while (usb.clock().now_ns() < until && out.size() < frames) {
    (void)camera.pump(5ms);
    if (const DepthFrame* f = camera.latest_depth()) out.push_back(*f);
  }
  return out;
}

/// Pumps for @p duration of simulated time.
void pump_for(SimUsbTransport& usb, KinectCamera& camera, std::chrono::milliseconds duration) {
  const std::int64_t until = usb.clock().now_ns() + duration.count() * 1'000'000;
  while (usb.clock().now_ns() < until) (void)camera.pump(5ms);
}

TEST(KinectCameraSim, ListsEachModelWithItsSerialAndMotor) {
  SimUsbTransport usb;
  usb.add_kinect(kinect_config(KinectModel::K1414));
  SimKinectConfig other = kinect_config(KinectModel::K1473);
  other.serial = "B00367707227042B";
  other.hub_ports = {2};
  usb.add_kinect(other);
  auto cameras = list_cameras(usb);
  ASSERT_TRUE(cameras.has_value());
  ASSERT_EQ(cameras.value().size(), 2U);
  EXPECT_EQ(cameras.value()[0].model, Model::K1414);
  EXPECT_EQ(cameras.value()[0].serial.view(), "A00364A11700045A");
  EXPECT_TRUE(cameras.value()[0].has_motor);
  EXPECT_EQ(cameras.value()[1].model, Model::K1473);
  // A 1473 camera reports zeros: the serial is the audio sibling's on the same hub.
  EXPECT_EQ(cameras.value()[1].serial.view(), "B00367707227042B");
  EXPECT_FALSE(cameras.value()[1].has_motor);
}

TEST(KinectCameraSim, OpensReadsCalibrationAndStreamsTheSimulatorsFramesBitForBit) {
  for (const KinectModel model : {KinectModel::K1414, KinectModel::K1473, KinectModel::K4W}) {
    SimUsbTransport usb;
    usb.add_kinect(kinect_config(model));
    auto camera = KinectCamera::open(usb);
    ASSERT_TRUE(camera.has_value()) << to_string(camera.error());
    KinectCamera& cam = *camera.value();
    const auto& cfg = usb.kinect(0).config();
    EXPECT_NEAR(cam.calibration().zero_plane.reference_pixel_size_mm, cfg.depth.ref_pix_mm, 1e-6);
    EXPECT_NEAR(cam.calibration().zero_plane.reference_distance_mm, cfg.depth.ref_dist_mm, 1e-4);
    EXPECT_NEAR(cam.calibration().zero_plane.dcmos_emitter_dist_cm, cfg.depth.emitter_dist_cm,
                1e-5);
    EXPECT_EQ(cam.calibration().const_shift, static_cast<std::uint16_t>(cfg.depth.const_shift));
    EXPECT_FLOAT_EQ(cam.calibration().zero_plane.dcmos_rcmos_dist_cm, 2.4F);

    ASSERT_TRUE(cam.start_depth().has_value());
    // The start script reached the device in the documented order.
    const auto& writes = usb.kinect(0).register_writes();
    const std::vector<std::pair<std::uint16_t, std::uint16_t>> want = {
        {0x105, 0}, {6, 0}, {0x12, 3}, {0x13, 1}, {0x14, 0x1E}, {6, 2}, {0x17, 0}};
    ASSERT_GE(writes.size(), want.size());
    EXPECT_TRUE(std::equal(want.begin(), want.end(), writes.end() - 7));

    const auto frames = collect(usb, cam, 3);
    ASSERT_EQ(frames.size(), 3U);
    std::vector<std::uint16_t> expected(DEPTH_PIXELS);
    for (const DepthFrame& f : frames) {
      EXPECT_TRUE(f.complete);
      usb.kinect(0).depth_raw_image(f.number, expected);
      EXPECT_EQ(f.raw, expected) << "frame " << f.number << " of model "
                                 << to_string(cam.info().model);
    }
    // 60 MHz device time: 2,000,000 ticks between frames at 30 Hz.
    EXPECT_NEAR(static_cast<double>(frames[2].device_ticks - frames[1].device_ticks) /
                    static_cast<double>(frames[2].number - frames[1].number),
                2e6, 2e6 * 0.01);
    ASSERT_TRUE(cam.stop_depth().has_value());
    EXPECT_EQ(usb.kinect(0).reg(6), 0);
  }
}

TEST(KinectCameraSim, ColourFramesArePairedByDeviceTimeAndArriveBitForBit) {
  SimUsbTransport usb;
  usb.add_kinect(kinect_config());
  CameraOptions options;
  options.colour = true;
  auto camera = KinectCamera::open(usb, options);
  ASSERT_TRUE(camera.has_value());
  KinectCamera& cam = *camera.value();
  ASSERT_TRUE(cam.start_depth().has_value());
  EXPECT_EQ(usb.kinect(0).reg(5), 1);  // the Bayer start script ran
  const auto frames = collect(usb, cam, 10);
  ASSERT_EQ(frames.size(), 10U);
  std::vector<std::uint8_t> bayer(DEPTH_PIXELS);
  std::vector<std::uint16_t> raw(DEPTH_PIXELS);
  for (const DepthFrame& f : frames) {
    ASSERT_TRUE(f.has_colour) << f.number;
    EXPECT_TRUE(f.colour_complete);
    const std::int64_t gap = static_cast<std::int64_t>(f.colour_ticks - f.device_ticks);
    EXPECT_LE(std::abs(gap), options.pair_tolerance_ticks) << f.number;
    usb.kinect(0).depth_raw_image(f.number, raw);
    EXPECT_EQ(f.raw, raw);
    usb.kinect(0).bayer_image(f.number, bayer);
    EXPECT_EQ(f.bayer, bayer) << f.number;
  }
  const CameraHealth h = cam.health();
  EXPECT_GE(h.frames_paired, 10U);
  // Every colour frame kept was either taken by a depth frame or counted as unpaired (the two
  // in the ring at the end may be neither yet).
  const std::uint64_t kept =
      h.colour.frames_complete + h.colour.frames_incomplete - h.colour_dropped;
  EXPECT_LE(h.frames_paired + h.colour_unpaired, kept);
  EXPECT_GE(h.frames_paired + h.colour_unpaired + 2, kept);
  EXPECT_EQ(h.depth_unpaired, 0U);
  ASSERT_TRUE(cam.stop_depth().has_value());
  EXPECT_EQ(usb.kinect(0).reg(5), 0);
}

TEST(KinectCameraSim, ColourLossLeavesDepthUnpairedAndCounted) {
  SimUsbTransport usb;
  SimKinectConfig c = kinect_config();
  c.faults.packets.drop_rate = 0.08;  // about 13 of 162 colour packets per frame: many dropped
  usb.add_kinect(c);
  CameraOptions options;
  options.colour = true;
  options.max_missing_packets = 242;  // keep every depth frame, however holed
  options.max_missing_colour_packets = 8;
  auto camera = KinectCamera::open(usb, options);
  ASSERT_TRUE(camera.has_value());
  KinectCamera& cam = *camera.value();
  ASSERT_TRUE(cam.start_depth().has_value());
  const auto frames = collect(usb, cam, 30, 3000ms);
  ASSERT_GE(frames.size(), 20U);
  std::size_t without = 0;
  for (const DepthFrame& f : frames) without += f.has_colour ? 0U : 1U;
  const CameraHealth h = cam.health();
  EXPECT_GT(h.colour_dropped, 0U);
  EXPECT_GT(without, 0U);
  EXPECT_GE(h.depth_unpaired, without);
}

TEST(KinectCameraSim, SurvivesJunkEmptyWrongTagAndStalledReplies) {
  SimUsbTransport usb;
  SimKinectConfig c = kinect_config();
  c.faults.junk_replies = 2;   // 512-byte junk, then
  c.faults.empty_replies = 3;  // 0-byte replies, before every real reply
  usb.add_kinect(c);
  auto camera = KinectCamera::open(usb);
  ASSERT_TRUE(camera.has_value()) << to_string(camera.error());
  KinectCamera& cam = *camera.value();
  EXPECT_GT(cam.control().stats().not_ready_polls, 0U);
  // One wrong tag and one stall: each costs a retry, the command still succeeds.
  auto faults = usb.kinect(0).faults();
  faults.wrong_tag_once = true;
  usb.kinect(0).set_faults(faults);
  ASSERT_TRUE(cam.control().write_register(0x17, 0).has_value());
  faults = usb.kinect(0).faults();
  faults.control_stalls = 1;
  usb.kinect(0).set_faults(faults);
  ASSERT_TRUE(cam.control().write_register(0x17, 0).has_value());
  EXPECT_GE(cam.control().stats().retries, 2U);
  EXPECT_EQ(cam.control().stats().bad_replies, 1U);
  EXPECT_GE(cam.control().stats().timeouts, 1U);
  // A device that never answers: bounded, named failure, no hang.
  faults = usb.kinect(0).faults();
  faults.control_stalls = 1000;
  usb.kinect(0).set_faults(faults);
  const std::int64_t before = usb.clock().now_ns();
  auto dead = cam.control().write_register(0x17, 0);
  ASSERT_FALSE(dead.has_value());
  EXPECT_EQ(dead.error().usb.code, UsbError::Code::TIMEOUT);
  // Bounded by the policy's command deadline (2 s) plus the one transfer in progress (0.5 s).
  EXPECT_LE(usb.clock().now_ns() - before, 2'600'000'000LL);
}

// A device that writes header bytes 6-7 differently (here: zero) loses nothing: libfreenect
// ignores them, and so does the assembler; the camera's health counts every disagreement.
TEST(KinectCameraSim, ASizeFieldThatDisagreesLosesNoFrameAndIsCounted) {
  SimUsbTransport usb;
  SimKinectConfig c = kinect_config();
  c.faults.packets.size_field_zero = true;
  usb.add_kinect(c);
  auto camera = KinectCamera::open(usb);
  ASSERT_TRUE(camera.has_value());
  KinectCamera& cam = *camera.value();
  ASSERT_TRUE(cam.start_depth().has_value());
  const auto frames = collect(usb, cam, 5, 3000ms);
  ASSERT_GE(frames.size(), 5U);
  std::vector<std::uint16_t> expected(DEPTH_PIXELS);
  for (const DepthFrame& f : frames) {
    EXPECT_TRUE(f.complete) << "frame " << f.number;
    usb.kinect(0).depth_raw_image(f.number, expected);
    EXPECT_EQ(f.raw, expected) << "frame " << f.number;
  }
  const CameraHealth h = cam.health();
  EXPECT_GE(h.depth.bad_size_field, 5U * 242U);
  const auto counters = health_counters(h);
  const auto mismatch = std::find_if(counters.begin(), counters.end(), [](const auto& k) {
    return std::string_view(k.name) == "size_field_mismatch";
  });
  ASSERT_NE(mismatch, counters.end());
  EXPECT_EQ(mismatch->value, h.depth.bad_size_field);
}

TEST(KinectCameraSim, PacketLossGivesDegradedFramesWithExactlyTheMissingPixelsMarked) {
  SimUsbTransport usb;
  SimKinectConfig c = kinect_config();
  c.faults.packets.drop_rate = 0.01;
  usb.add_kinect(c);
  auto camera = KinectCamera::open(usb);
  ASSERT_TRUE(camera.has_value());
  KinectCamera& cam = *camera.value();
  ASSERT_TRUE(cam.start_depth().has_value());
  const auto frames = collect(usb, cam, 20, 3000ms);
  ASSERT_GE(frames.size(), 15U);
  std::vector<std::uint16_t> expected(DEPTH_PIXELS);
  std::size_t degraded = 0;
  for (const DepthFrame& f : frames) {
    usb.kinect(0).depth_raw_image(f.number, expected);
    std::size_t wrong = 0, masked = 0;
    for (std::size_t i = 0; i < DEPTH_PIXELS; ++i) {
      if (f.raw[i] == expected[i]) continue;
      if (f.raw[i] == RAW_NO_READING) {
        ++masked;  // a pixel of a lost packet: "no reading", never a made-up value
      } else {
        ++wrong;
      }
    }
    EXPECT_EQ(wrong, 0U) << "frame " << f.number;
    if (!f.complete) {
      ++degraded;
      EXPECT_GT(f.missing_packets, 0U);
      // Each lost packet hides at most ceil(1748 * 8 / 11) + 1 pixels.
      EXPECT_LE(masked, std::size_t{f.missing_packets} * 1273U);
    } else {
      EXPECT_EQ(masked, 0U);
    }
  }
  EXPECT_GT(degraded, 0U);
  const CameraHealth h = cam.health();
  EXPECT_GT(h.depth.lost_packets, 0U);
  EXPECT_EQ(h.frames_degraded, h.depth.frames_incomplete - h.frames_dropped);
}

TEST(KinectCameraSim, UnplugIsCountedAndTheCameraComesBackStreaming) {
  SimUsbTransport usb;
  usb.add_kinect(kinect_config());
  CameraOptions options;
  options.reopen_interval_ns = 200'000'000;
  auto camera = KinectCamera::open(usb, options);
  ASSERT_TRUE(camera.has_value());
  KinectCamera& cam = *camera.value();
  ASSERT_TRUE(cam.start_depth().has_value());
  ASSERT_EQ(collect(usb, cam, 2).size(), 2U);
  usb.unplug(0);
  pump_for(usb, cam, 200ms);
  CameraHealth h = cam.health();
  EXPECT_EQ(h.unplugs, 1U);
  EXPECT_TRUE(h.device_lost);
  EXPECT_FALSE(h.streaming);
  usb.replug(0);
  const auto after = collect(usb, cam, 3, 3000ms);
  ASSERT_EQ(after.size(), 3U);
  h = cam.health();
  EXPECT_EQ(h.reopens, 1U);
  EXPECT_FALSE(h.device_lost);
  EXPECT_TRUE(h.streaming);
  std::vector<std::uint16_t> expected(DEPTH_PIXELS);
  usb.kinect(0).depth_raw_image(after.back().number, expected);
  EXPECT_EQ(after.back().raw, expected);
}

TEST(KinectCameraSim, WatchdogRestartsAStreamThatGoesSilent) {
  SimUsbTransport usb;
  usb.add_kinect(kinect_config());
  CameraOptions options;
  options.watchdog_ns = 300'000'000;
  auto camera = KinectCamera::open(usb, options);
  ASSERT_TRUE(camera.has_value());
  KinectCamera& cam = *camera.value();
  ASSERT_TRUE(cam.start_depth().has_value());
  ASSERT_EQ(collect(usb, cam, 2).size(), 2U);
  // The firmware stops sending (as if the depth register were cleared behind our back).
  usb.kinect(0).power_cycle();
  pump_for(usb, cam, 500ms);
  EXPECT_GE(cam.health().watchdog_restarts, 1U);
  EXPECT_EQ(collect(usb, cam, 2).size(), 2U);
}

TEST(KinectCameraSim, FramePathDoesNotAllocateAfterWarmUp) {
  SimUsbTransport usb;
  SimKinectConfig c = kinect_config();
  c.faults.packets.drop_rate = 0.005;  // the degraded path too
  usb.add_kinect(c);
  auto camera = KinectCamera::open(usb);
  ASSERT_TRUE(camera.has_value());
  KinectCamera& cam = *camera.value();
  ASSERT_TRUE(cam.start_depth().has_value());
  ASSERT_EQ(collect(usb, cam, 3).size(), 3U);  // warm-up
  std::size_t taken = 0;
  test::g_allocations = 0;
  test::g_counting = true;
  const std::int64_t until = usb.clock().now_ns() + 2'000'000'000;
  while (usb.clock().now_ns() < until) {  // 2 s of simulated time: ~60 frames
    (void)cam.pump(5ms);
    if (cam.latest_depth() != nullptr) ++taken;
  }
  test::g_counting = false;
  EXPECT_EQ(test::g_allocations.load(), 0U);
  EXPECT_GE(taken, 50U);
}

TEST(KinectDeviceSim, UsbThreadPublishesFramesToAnotherThread) {
  auto usb = std::make_unique<SimUsbTransport>();
  usb->add_kinect(kinect_config());
  DeviceOptions options;
  options.pace_to_wall_clock = true;
  auto device = KinectDevice::start(std::move(usb), options);
  ASSERT_TRUE(device.has_value()) << to_string(device.error());
  std::size_t got = 0;
  std::uint64_t last = 0;
  const auto until = std::chrono::steady_clock::now() + 3s;
  while (got < 5 && std::chrono::steady_clock::now() < until) {
    if (const DepthFrame* f = device.value()->latest_depth()) {
      if (got > 0) { EXPECT_GT(f->number, last); }
      last = f->number;
      ++got;
    }
    std::this_thread::sleep_for(2ms);
  }
  EXPECT_EQ(got, 5U);
  EXPECT_TRUE(device.value()->health().streaming);
}

TEST(KinectCameraSim, NoCameraIsANamedError) {
  SimUsbTransport usb;
  auto camera = KinectCamera::open(usb);
  ASSERT_FALSE(camera.has_value());
  EXPECT_EQ(camera.error().code, KinectError::Code::NO_CAMERA);
  usb.add_kinect(kinect_config());
  CameraOptions options;
  options.serial = "NOT-THIS-ONE";
  EXPECT_EQ(KinectCamera::open(usb, options).error().code, KinectError::Code::NO_CAMERA);
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
