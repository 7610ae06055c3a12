// Hardware tests of the JACO driver: they run only with JACO_HW=1 on a machine with a JACO plugged
// in, and the motion test only with JACO_WORKSPACE_CLEAR=yes as well (a person has checked that
// nothing and nobody is within reach). Everywhere else, CI included, they report SKIPPED, not
// passed (USB_TESTING.md 4).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string_view>
#include <thread>

#include "drivers/jaco/jaco_arm.hpp"
#include "drivers/usb/libusb_transport.hpp"

namespace orthoflow::drivers::jaco {
namespace {

bool env_is(const char* name, std::string_view value) {
  const char* v = std::getenv(name);
  return v != nullptr && std::string_view(v) == value;
}

std::unique_ptr<JacoArm> open_real_arm() {
  auto usb = LibusbTransport::create();
  EXPECT_TRUE(usb.has_value());
  if (!usb.has_value()) return nullptr;
  auto arms = list_arms(*usb.value());
  EXPECT_TRUE(arms.has_value() && !arms.value().empty()) << "no JACO on USB";
  if (!arms.has_value() || arms.value().empty()) return nullptr;
  const UsbDeviceInfo device = arms.value().front();
  auto arm = JacoArm::start(std::move(usb).value(), device, ArmOptions{});
  EXPECT_TRUE(arm.has_value()) << (arm.has_value() ? "" : to_string(arm.error()));
  return arm.has_value() ? std::move(arm).value() : nullptr;
}

TEST(JacoHardware, ReadsIdentityAndStateWithoutMoving) {
  if (!env_is("JACO_HW", "1")) GTEST_SKIP() << "set JACO_HW=1 with a JACO plugged in";
  auto arm = open_real_arm();
  ASSERT_NE(arm, nullptr);
  EXPECT_FALSE(arm->identity().client.serial.view().empty());
  EXPECT_GT(arm->identity().firmware.dsp.major, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const ArmSnapshot s = arm->snapshot();
  EXPECT_FALSE(s.fault) << to_string(s.fault_error);
  EXPECT_GT(s.cycle, 20U);
  EXPECT_GT(s.sensors.voltage_v, 18.0F);
  EXPECT_LT(s.sensors.voltage_v, 30.0F);
  EXPECT_TRUE(jaco_joint_limits().contains(s.joints));
}

TEST(JacoHardware, MovesTheWristFiveDegreesAndStopsOnTheWatchdog) {
  if (!env_is("JACO_HW", "1")) GTEST_SKIP() << "set JACO_HW=1 with a JACO plugged in";
  if (!env_is("JACO_WORKSPACE_CLEAR", "yes"))
    GTEST_SKIP() << "motion test: set JACO_WORKSPACE_CLEAR=yes once the workspace is clear";
  auto arm = open_real_arm();
  ASSERT_NE(arm, nullptr);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ArmCommand move;
  move.kind = ArmCommand::Kind::MOVE_JOINTS;
  move.joints = arm->snapshot().joints;
  move.joints[5] += 5.0;  // the last wrist joint: the smallest motion there is
  move.speed_fraction = 0.3;
  ASSERT_TRUE(arm->submit(move).has_value());
  ArmSnapshot s;
  for (int i = 0; i < 250; ++i) {  // 5 s
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    arm->keep_alive();
    s = arm->snapshot();
    if (i > 5 && s.control == ControlState::IDLE) break;
  }
  EXPECT_EQ(s.last_stop, StopReason::REACHED);
  EXPECT_NEAR(s.joints[5], move.joints[5], 0.5);
  // Back, then let the watchdog stop it half way.
  move.joints[5] -= 5.0;
  ASSERT_TRUE(arm->submit(move).has_value());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  s = arm->snapshot();
  EXPECT_EQ(s.last_stop, StopReason::WATCHDOG);
  const double stopped = s.joints[5];
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_NEAR(arm->snapshot().joints[5], stopped, 0.2);
}

}  // namespace
}  // namespace orthoflow::drivers::jaco
