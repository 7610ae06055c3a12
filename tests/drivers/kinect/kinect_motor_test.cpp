// The 1414 motor, LED and accelerometer (drivers/kinect/kinect_motor.hpp), part 1: the pure codec
// on hand-made bytes (specs/USB_TESTING.md 3.2, "Motor") and the sibling rule (KINECT_V1.md 1).
// Part 2, the driver against the simulated motor, is kinect_motor_sim_test.cpp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "drivers/kinect/kinect_motor.hpp"
#include "drivers/kinect/kinect_siblings.hpp"

namespace orthoflow::drivers::kinect {
namespace {

std::int16_t as_signed(std::uint16_t v) { return static_cast<std::int16_t>(v); }

std::array<std::byte, 10> state_bytes(std::int16_t x, std::int16_t y, std::int16_t z,
                                      std::uint8_t tilt, std::uint8_t status) {
  std::array<std::byte, 10> b{};
  b[0] = std::byte{0xAA};  // bytes 0-1: unused, must not matter
  b[1] = std::byte{0x55};
  const std::array<std::int16_t, 3> axes{x, y, z};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto u = static_cast<std::uint16_t>(axes[i]);
    b[2 + 2 * i] = std::byte{static_cast<std::uint8_t>(u >> 8)};
    b[3 + 2 * i] = std::byte{static_cast<std::uint8_t>(u & 0xFFU)};
  }
  b[8] = std::byte{tilt};
  b[9] = std::byte{status};
  return b;
}

// ---- Pure codec ---------------------------------------------------------------------------------

TEST(KinectMotorCodec, TiltEncodesTwiceTheDegreesSignedAndClampsAt31) {
  for (int deg = -31; deg <= 31; ++deg) EXPECT_EQ(as_signed(encode_tilt(deg)), 2 * deg) << deg;
  EXPECT_EQ(encode_tilt(-1.0), 0xFFFE);  // two's complement on the wire
  EXPECT_EQ(as_signed(encode_tilt(40.0)), 62);
  EXPECT_EQ(as_signed(encode_tilt(-40.0)), -62);
  EXPECT_EQ(as_signed(encode_tilt(1e9)), 62);
  EXPECT_EQ(encode_tilt(std::nan("")), 0);
}

TEST(KinectMotorCodec, TiltRoundsToTheNearestHalfDegree) {
  EXPECT_EQ(as_signed(encode_tilt(10.2)), 20);
  EXPECT_EQ(as_signed(encode_tilt(10.3)), 21);
  EXPECT_EQ(as_signed(encode_tilt(10.25)), 21);  // halves away from zero
  EXPECT_EQ(as_signed(encode_tilt(-10.25)), -21);
  EXPECT_EQ(as_signed(encode_tilt(-0.2)), 0);
  EXPECT_EQ(as_signed(encode_tilt(30.9)), 62);
}

TEST(KinectMotorCodec, LedCodesAndNames) {
  EXPECT_EQ(static_cast<int>(LedMode::OFF), 0);
  EXPECT_EQ(static_cast<int>(LedMode::GREEN), 1);
  EXPECT_EQ(static_cast<int>(LedMode::RED), 2);
  EXPECT_EQ(static_cast<int>(LedMode::YELLOW), 3);
  EXPECT_EQ(static_cast<int>(LedMode::BLINK_GREEN), 4);
  EXPECT_EQ(static_cast<int>(LedMode::BLINK_RED_YELLOW), 6);
  for (const LedMode m : {LedMode::OFF, LedMode::GREEN, LedMode::RED, LedMode::YELLOW,
                          LedMode::BLINK_GREEN, LedMode::BLINK_RED_YELLOW})
    EXPECT_EQ(parse_led_mode(to_string(m)), m) << to_string(m);
  EXPECT_STREQ(to_string(LedMode::BLINK_RED_YELLOW), "blink-red-yellow");
  EXPECT_FALSE(parse_led_mode("blue").has_value());
  EXPECT_FALSE(parse_led_mode("").has_value());
}

TEST(KinectMotorCodec, StateDecodesBigEndianAccelTiltAndStatus) {
  const auto bytes = state_bytes(-12, 819, -300, 0x28, 0x04);  // tilt 40 half degrees, moving
  // Big-endian on the wire: -12 = 0xFFF4, 819 = 0x0333.
  EXPECT_EQ(bytes[2], std::byte{0xFF});
  EXPECT_EQ(bytes[3], std::byte{0xF4});
  EXPECT_EQ(bytes[4], std::byte{0x03});
  EXPECT_EQ(bytes[5], std::byte{0x33});
  const auto s = decode_motor_state(bytes);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->accel_counts[0], -12);
  EXPECT_EQ(s->accel_counts[1], 819);
  EXPECT_EQ(s->accel_counts[2], -300);
  EXPECT_DOUBLE_EQ(s->accel_g[1], 1.0);  // 819 counts = 1 g
  EXPECT_DOUBLE_EQ(s->accel_mps2[1], 9.80665);
  EXPECT_DOUBLE_EQ(s->accel_g[2], -300.0 / 819.0);
  ASSERT_TRUE(s->tilt_deg.has_value());
  EXPECT_DOUBLE_EQ(*s->tilt_deg, 20.0);
  EXPECT_EQ(s->status, TiltStatus::MOVING);
  EXPECT_EQ(s->status_raw, 0x04);
}

TEST(KinectMotorCodec, StateNegativeTiltStatusesAndNoReading) {
  auto s = decode_motor_state(state_bytes(0, 0, 0, 0xC5, 0x00));  // -59 half degrees
  ASSERT_TRUE(s.has_value());
  EXPECT_DOUBLE_EQ(*s->tilt_deg, -29.5);
  EXPECT_EQ(s->status, TiltStatus::STOPPED);
  s = decode_motor_state(state_bytes(0, 0, 0, 0x3E, 0x01));
  EXPECT_EQ(s->status, TiltStatus::AT_LIMIT);
  s = decode_motor_state(state_bytes(-32768, 32767, 0, 0x80, 0x08));  // a book's "stall"
  EXPECT_EQ(s->accel_counts[0], -32768);
  EXPECT_EQ(s->accel_counts[1], 32767);
  EXPECT_FALSE(s->tilt_deg.has_value());  // -128: no reading
  EXPECT_EQ(s->tilt_raw, -128);
  EXPECT_EQ(s->status, TiltStatus::UNKNOWN);
  EXPECT_EQ(s->status_raw, 0x08);
  EXPECT_STREQ(to_string(TiltStatus::UNKNOWN), "unknown");
}

TEST(KinectMotorCodec, StateOfAnyOtherLengthIsRefused) {
  const auto bytes = state_bytes(1, 2, 3, 4, 0);
  std::vector<std::byte> longer(bytes.begin(), bytes.end());
  longer.push_back(std::byte{0});
  EXPECT_FALSE(decode_motor_state({}).has_value());
  EXPECT_FALSE(decode_motor_state(std::span(bytes).first(9)).has_value());
  EXPECT_FALSE(decode_motor_state(longer).has_value());
}

TEST(KinectMotorCodec, SiblingRuleSameHubThenOnlyOnBusThenOnlyOne) {
  auto dev = [](std::uint8_t bus, std::vector<std::uint8_t> ports) {
    UsbDeviceInfo d;
    d.bus = bus;
    d.port_depth = static_cast<std::uint8_t>(ports.size());
    std::copy(ports.begin(), ports.end(), d.port_path.begin());
    return d;
  };
  const UsbDeviceInfo camera = dev(1, {4, 1});
  const UsbDeviceInfo same_hub = dev(1, {4, 3});
  const UsbDeviceInfo other_hub = dev(1, {5, 3});
  const UsbDeviceInfo other_bus = dev(2, {4, 3});
  EXPECT_EQ(find_sibling(camera, {&other_hub, &same_hub, &other_bus}), &same_hub);
  EXPECT_EQ(find_sibling(camera, {&other_hub, &other_bus}), &other_hub);  // only one on bus 1
  EXPECT_EQ(find_sibling(camera, {&other_bus}), &other_bus);              // only one at all
  const UsbDeviceInfo other_bus_too = dev(2, {5, 3});
  EXPECT_EQ(find_sibling(camera, {&other_bus, &other_bus_too}), nullptr);  // ambiguous
  EXPECT_EQ(find_sibling(camera, {}), nullptr);
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
