// The 1414 motor, LED and accelerometer (drivers/kinect/kinect_motor.hpp), part 2: KinectMotor
// against the simulated motor of simulation/ on simulated time. The simulator implements
// KINECT_V1.md 11 and has never been compared with a real Kinect, so these tests prove the driver
// against the brief only. Part 1, the pure codec, is kinect_motor_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>

#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_motor.hpp"
#include "simulation/devices/sim_usb_transport.hpp"

namespace orthoflow::drivers::kinect {
namespace {

using simulation::KinectModel;
using simulation::SimKinectConfig;
using simulation::SimUsbTransport;
using namespace std::chrono_literals;

constexpr double PI = 3.14159265358979323846;

// ---- Against the simulated motor ----------------------------------------------------------------

CameraInfo first_camera(SimUsbTransport& usb) {
  auto cameras = list_cameras(usb);
  EXPECT_TRUE(cameras.has_value());
  EXPECT_FALSE(cameras.value().empty());
  return cameras.value().front();
}

std::unique_ptr<KinectMotor> open_motor(SimUsbTransport& usb, const CameraInfo& camera) {
  auto motor = KinectMotor::open(usb, camera);
  EXPECT_TRUE(motor.has_value()) << to_string(motor.error());
  return motor.has_value() ? std::move(motor.value()) : nullptr;
}

TEST(KinectMotorSim, OpensTheMotorOfA1414AndRefusesA1473OrK4W) {
  SimUsbTransport usb;
  usb.add_kinect(SimKinectConfig{});
  EXPECT_TRUE(first_camera(usb).has_motor);  // list_cameras uses the same find_sibling rule
  auto motor = open_motor(usb, first_camera(usb));
  ASSERT_NE(motor, nullptr);
  EXPECT_EQ(motor->info().product, PID_MOTOR);
  EXPECT_TRUE(same_parent_hub(motor->info(), first_camera(usb).usb));
  for (const KinectModel model : {KinectModel::K1473, KinectModel::K4W}) {
    SimUsbTransport other;
    SimKinectConfig c;
    c.model = model;
    other.add_kinect(c);
    EXPECT_FALSE(first_camera(other).has_motor);
    EXPECT_EQ(first_camera(other).serial.view(), c.serial);  // the audio sibling's serial
    auto refused = KinectMotor::open(other, first_camera(other));
    ASSERT_FALSE(refused.has_value());
    EXPECT_EQ(refused.error().code, KinectError::Code::USB);
    EXPECT_EQ(refused.error().usb.code, UsbError::Code::NOT_SUPPORTED);
    EXPECT_NE(to_string(refused.error()).find("audio firmware"), std::string::npos);
  }
}

TEST(KinectMotorSim, TiltsToTwentyDegreesReportingMovingThenStopped) {
  SimUsbTransport usb;
  usb.add_kinect(SimKinectConfig{});  // slews at 15 deg/s
  auto motor = open_motor(usb, first_camera(usb));
  ASSERT_NE(motor, nullptr);
  const std::int64_t start = usb.clock().now_ns();
  ASSERT_TRUE(motor->set_tilt(20.0).has_value());
  EXPECT_DOUBLE_EQ(usb.kinect(0).target_tilt_deg(), 20.0);
  usb.run_for(400ms);
  auto moving = motor->read_state();
  ASSERT_TRUE(moving.has_value()) << to_string(moving.error());
  EXPECT_EQ(moving->status, TiltStatus::MOVING);
  ASSERT_TRUE(moving->tilt_deg.has_value());
  EXPECT_NEAR(*moving->tilt_deg, usb.kinect(0).tilt_deg(usb.clock().now_ns()), 0.5);
  EXPECT_GT(*moving->tilt_deg, 4.0);
  EXPECT_LT(*moving->tilt_deg, 8.0);

  auto still = motor->wait_until_still(5000ms);
  ASSERT_TRUE(still.has_value()) << to_string(still.error());
  EXPECT_EQ(still->status, TiltStatus::STOPPED);
  ASSERT_TRUE(still->tilt_deg.has_value());
  EXPECT_NEAR(*still->tilt_deg, 20.0, 0.5);
  EXPECT_NEAR(usb.kinect(0).tilt_deg(usb.clock().now_ns()), *still->tilt_deg, 0.5);
  // 20 degrees at 15 deg/s: 1.33 s, noticed within one 50 ms poll; polled, not spun.
  const double seconds = static_cast<double>(usb.clock().now_ns() - start) * 1e-9;
  EXPECT_GE(seconds, 1.33);
  EXPECT_LE(seconds, 1.33 + 0.06);
  EXPECT_LE(motor->stats().polls, 1.0 / 0.05 + 2.0);
  auto again = motor->read_state();
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->status, TiltStatus::STOPPED);
}

TEST(KinectMotorSim, AccelerometerIsOneGAndAgreesWithTheTilt) {
  SimUsbTransport usb;
  SimKinectConfig level;
  level.mount_pitch_deg = 0.0;  // the accelerometer then reads the motor angle alone
  usb.add_kinect(level);
  auto motor = open_motor(usb, first_camera(usb));
  ASSERT_NE(motor, nullptr);
  for (const double deg : {0.0, 20.0, -27.5}) {
    ASSERT_TRUE(motor->set_tilt(deg).has_value());
    auto s = motor->wait_until_still(5000ms);
    ASSERT_TRUE(s.has_value()) << to_string(s.error());
    const auto& g = s->accel_g;
    EXPECT_NEAR(std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]), 1.0, 0.01) << deg;
    const double m =
        std::sqrt(s->accel_mps2[0] * s->accel_mps2[0] + s->accel_mps2[1] * s->accel_mps2[1] +
                  s->accel_mps2[2] * s->accel_mps2[2]);
    EXPECT_NEAR(m, 9.80665, 0.1) << deg;
    // The simulator models gravity in a head pitched about X: Y = cos, Z = sin of the tilt.
    EXPECT_NEAR(std::atan2(g[2], g[1]) * 180.0 / PI, deg, 0.2) << deg;
    EXPECT_NEAR(*s->tilt_deg, deg, 0.5);
  }
}

TEST(KinectMotorSim, LedChangesTheSimulatorsLed) {
  SimUsbTransport usb;
  usb.add_kinect(SimKinectConfig{});
  auto motor = open_motor(usb, first_camera(usb));
  ASSERT_NE(motor, nullptr);
  for (const LedMode m : {LedMode::GREEN, LedMode::RED, LedMode::YELLOW, LedMode::BLINK_GREEN,
                          LedMode::BLINK_RED_YELLOW, LedMode::OFF}) {
    ASSERT_TRUE(motor->set_led(m).has_value()) << to_string(m);
    EXPECT_EQ(usb.kinect(0).led(), static_cast<std::uint8_t>(m));
  }
}

TEST(KinectMotorSim, TiltBeyondTheLimitIsRefusedAndNothingSent) {
  SimUsbTransport usb;
  usb.add_kinect(SimKinectConfig{});
  auto motor = open_motor(usb, first_camera(usb));
  ASSERT_NE(motor, nullptr);
  for (const double bad : {31.5, -40.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    auto refused = motor->set_tilt(bad);
    ASSERT_FALSE(refused.has_value());
    EXPECT_EQ(refused.error().code, KinectError::Code::INVALID_ARGUMENT);
  }
  EXPECT_EQ(motor->stats().requests, 0U);
  EXPECT_DOUBLE_EQ(usb.kinect(0).target_tilt_deg(), 0.0);
  EXPECT_TRUE(motor->set_tilt(-31.0).has_value());  // the limit itself is allowed
}

TEST(KinectMotorSim, AStalledControlIsATimeoutNotAHang) {
  SimUsbTransport usb;
  usb.add_kinect(SimKinectConfig{});
  auto motor = open_motor(usb, first_camera(usb));
  ASSERT_NE(motor, nullptr);
  auto faults = usb.kinect(0).faults();
  faults.control_stalls = 3;
  usb.kinect(0).set_faults(faults);
  std::int64_t before = usb.clock().now_ns();
  auto tilt = motor->set_tilt(10.0);
  ASSERT_FALSE(tilt.has_value());
  EXPECT_EQ(tilt.error().code, KinectError::Code::USB);
  EXPECT_EQ(tilt.error().usb.code, UsbError::Code::TIMEOUT);
  EXPECT_EQ(tilt.error().opcode, 0x31);
  EXPECT_LE(usb.clock().now_ns() - before, 501'000'000);   // one 500 ms transfer timeout
  EXPECT_DOUBLE_EQ(usb.kinect(0).target_tilt_deg(), 0.0);  // the request was lost
  auto led = motor->set_led(LedMode::RED);
  ASSERT_FALSE(led.has_value());
  EXPECT_EQ(led.error().usb.code, UsbError::Code::TIMEOUT);
  before = usb.clock().now_ns();
  auto state = motor->wait_until_still(5000ms);  // the failed read ends the wait at once
  ASSERT_FALSE(state.has_value());
  EXPECT_EQ(state.error().usb.code, UsbError::Code::TIMEOUT);
  EXPECT_LE(usb.clock().now_ns() - before, 501'000'000);
  EXPECT_EQ(motor->stats().timeouts, 3U);
  EXPECT_TRUE(motor->set_led(LedMode::RED).has_value());  // the device answers again
}

TEST(KinectMotorSim, WaitUntilStillIsBoundedByItsTimeout) {
  SimUsbTransport usb;
  usb.add_kinect(SimKinectConfig{});
  auto motor = open_motor(usb, first_camera(usb));
  ASSERT_NE(motor, nullptr);
  ASSERT_TRUE(motor->set_tilt(30.0).has_value());  // 2 s of travel
  const std::int64_t before = usb.clock().now_ns();
  auto state = motor->wait_until_still(500ms);
  ASSERT_FALSE(state.has_value());
  EXPECT_EQ(state.error().code, KinectError::Code::USB);
  EXPECT_EQ(state.error().usb.code, UsbError::Code::TIMEOUT);
  EXPECT_EQ(state.error().usb.operation, "kinect motor wait_until_still");
  const std::int64_t waited = usb.clock().now_ns() - before;
  EXPECT_GE(waited, 500'000'000);
  EXPECT_LE(waited, 502'000'000);
}

TEST(KinectMotorSim, WaitingPumpsTheCamerasStreamOnTheSameTransport) {
  SimUsbTransport usb;
  usb.add_kinect(SimKinectConfig{});
  auto camera = KinectCamera::open(usb);
  ASSERT_TRUE(camera.has_value()) << to_string(camera.error());
  ASSERT_TRUE(camera.value()->start_depth().has_value());
  auto motor = open_motor(usb, camera.value()->info());
  ASSERT_NE(motor, nullptr);
  ASSERT_TRUE(motor->set_tilt(-15.0).has_value());
  auto still = motor->wait_until_still(5000ms);  // 1 s of travel
  ASSERT_TRUE(still.has_value()) << to_string(still.error());
  EXPECT_NEAR(*still->tilt_deg, -15.0, 0.5);
  ASSERT_TRUE(camera.value()->pump(0ms).has_value());
  EXPECT_GE(camera.value()->health().frames_delivered, 25U);  // ~30 Hz all along
}

TEST(KinectMotorSim, TwoKinectsOnTwoHubsEachGetTheirOwnMotor) {
  SimUsbTransport usb;
  SimKinectConfig a;
  a.hub_ports = {1};
  SimKinectConfig b;
  b.serial = "B00364A11700045B";
  b.hub_ports = {2};
  usb.add_kinect(a);
  usb.add_kinect(b);
  auto cameras = list_cameras(usb);
  ASSERT_TRUE(cameras.has_value());
  ASSERT_EQ(cameras.value().size(), 2U);
  for (std::size_t i = 0; i < 2; ++i) {
    const CameraInfo& cam = cameras.value()[i];
    auto motor = open_motor(usb, cam);
    ASSERT_NE(motor, nullptr);
    EXPECT_TRUE(same_parent_hub(motor->info(), cam.usb));
    const std::size_t index = cam.serial.view() == b.serial ? 1 : 0;
    ASSERT_TRUE(motor->set_led(i == 0 ? LedMode::GREEN : LedMode::RED).has_value());
    EXPECT_EQ(usb.kinect(index).led(), i == 0 ? 1 : 2);
    EXPECT_EQ(usb.kinect(1 - index).led(), i == 0 ? 0 : 1);  // the other one is untouched
  }
}

TEST(KinectMotorSim, NoMatchingMotorIsNotFound) {
  SimUsbTransport usb;
  SimKinectConfig a;
  a.hub_ports = {1};
  SimKinectConfig b;
  b.serial = "B00364A11700045B";
  b.hub_ports = {2};
  usb.add_kinect(a);
  usb.add_kinect(b);
  // A camera on another bus, two motors on bus 1: no rule picks one.
  CameraInfo stray = first_camera(usb);
  stray.usb.bus = 9;
  auto motor = KinectMotor::open(usb, stray);
  ASSERT_FALSE(motor.has_value());
  EXPECT_EQ(motor.error().usb.code, UsbError::Code::NOT_FOUND);
}

// The simulated Kinect stands on a bracket pitched like the default scene's camera, so that its
// accelerometer's "up" agrees with the table it renders (the table verdict, issue 50, uses it).
TEST(KinectMotorSim, AccelerometerAddsTheMountPitch) {
  for (const std::optional<double> mount :
       {std::optional<double>(-40.0), std::optional<double>()}) {
    SimUsbTransport usb;
    SimKinectConfig config;
    config.mount_pitch_deg = mount;  // nullopt: the default scene's own pitch
    usb.add_kinect(config);
    auto motor = open_motor(usb, first_camera(usb));
    ASSERT_NE(motor, nullptr);
    auto s = motor->wait_until_still(5000ms);
    ASSERT_TRUE(s.has_value()) << to_string(s.error());
    const double pitch = std::atan2(s->accel_g[2], s->accel_g[1]) * 180.0 / PI;
    const double expected = usb.kinect(0).mount_pitch_deg();
    EXPECT_NEAR(pitch, expected, 0.2);
    EXPECT_NEAR(*s->tilt_deg, 0.0, 0.5);  // the tilt byte is the motor angle alone
    if (mount) {
      EXPECT_DOUBLE_EQ(expected, -40.0);
    } else {  // the default scene looks 30-60 degrees down at its table
      EXPECT_LT(expected, -29.9);
      EXPECT_GT(expected, -60.1);
    }
  }
}

}  // namespace
}  // namespace orthoflow::drivers::kinect