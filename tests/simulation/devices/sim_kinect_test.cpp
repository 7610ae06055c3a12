// The simulated Kinect v1 behind SimUsbTransport, driven only through drivers::UsbTransport with
// hand-built bytes: enumeration, the seam contract, the GM command protocol and its faults, the
// motor. Streams and packet faults: sim_kinect_stream_test.cpp.
#include <bit>
#include <cmath>

#include "sim_kinect_test_support.hpp"

namespace orthoflow::simulation::test {
namespace {

using Code = UsbError::Code;

TEST(SimKinect, Enumerate1414FindsCameraMotorAndAudioBehindOneHub) {
  SimUsbTransport usb;
  usb.add_kinect(cheap_config());
  auto cams = usb.enumerate(0x045E, 0x02AE);
  auto motors = usb.enumerate(0x045E, 0x02B0);
  auto all = usb.enumerate(0x045E, std::nullopt);
  ASSERT_TRUE(cams && motors && all);
  ASSERT_EQ(cams->size(), 1U);
  ASSERT_EQ(motors->size(), 1U);
  EXPECT_EQ(all->size(), 3U);  // camera, motor, audio
  const UsbDeviceInfo& cam = cams->front();
  const UsbDeviceInfo& motor = motors->front();
  EXPECT_EQ(cam.bcd_device, 0x010B);
  EXPECT_EQ(cam.interface_count, 1);
  EXPECT_EQ(cam.serial.view().size(), 16U);
  EXPECT_NE(cam.serial.view(), "0000000000000000");
  EXPECT_EQ(cam.bus, motor.bus);
  EXPECT_NE(cam.address, motor.address);
  EXPECT_TRUE(drivers::same_parent_hub(cam, motor));
  EXPECT_TRUE(usb.enumerate(0x22CD, std::nullopt)->empty());
}

TEST(SimKinect, Enumerate1473AndK4wHaveNoMotorAndAZeroCameraSerial) {
  SimUsbTransport usb;
  SimKinectConfig k1473 = cheap_config(KinectModel::K1473);
  SimKinectConfig k4w = cheap_config(KinectModel::K4W);
  k4w.hub_ports = {2};
  usb.add_kinect(k1473);
  usb.add_kinect(k4w);
  auto cams = usb.enumerate(0x045E, 0x02AE);
  auto k4w_cams = usb.enumerate(0x045E, 0x02BF);
  ASSERT_TRUE(cams && k4w_cams);
  ASSERT_EQ(cams->size(), 1U);
  ASSERT_EQ(k4w_cams->size(), 1U);
  EXPECT_NE(cams->front().bcd_device, 0x010B);
  EXPECT_EQ(cams->front().serial.view(), "0000000000000000");
  EXPECT_TRUE(usb.enumerate(0x045E, 0x02B0)->empty());
  EXPECT_EQ(usb.enumerate(0x045E, 0x02AD)->size(), 1U);
  EXPECT_FALSE(drivers::same_parent_hub(cams->front(), k4w_cams->front()));
  EXPECT_NE(cams->front().address, k4w_cams->front().address);
  // K4W streams only in alternate setting 1.
  auto h_result = usb.open(k4w_cams->front());
  ASSERT_TRUE(h_result);
  const UsbDeviceHandle& h = *h_result;
  ASSERT_TRUE(usb.detach_kernel_driver(h, 0));
  ASSERT_TRUE(usb.claim_interface(h, 0));
  Collector c;
  EXPECT_EQ(usb.start_iso(h, 0x82, {}, c.callback()).error().code, Code::NOT_FOUND);
  ASSERT_TRUE(usb.set_alt_setting(h, 0, 1));
  EXPECT_TRUE(usb.start_iso(h, 0x82, {}, c.callback()));
}

TEST(SimKinect, HandlesFollowTheSeamContract) {
  SimUsbTransport usb;
  SimUsbTransport other;
  usb.add_kinect(cheap_config());
  const UsbDeviceInfo info = usb.enumerate(0x045E, 0x02AE)->front();
  auto cam_result = usb.open(info);
  auto cam2_result = usb.open(info);
  ASSERT_TRUE(cam_result && cam2_result);
  const UsbDeviceHandle& cam = *cam_result;
  const UsbDeviceHandle& cam2 = *cam2_result;
  UsbDeviceInfo gone = info;
  gone.address = 99;
  EXPECT_EQ(usb.open(gone).error().code, Code::NO_DEVICE);
  EXPECT_EQ(other.claim_interface(cam, 0).error().code, Code::NOT_OPEN);
  EXPECT_EQ(usb.claim_interface(UsbDeviceHandle{}, 0).error().code, Code::NOT_OPEN);
  EXPECT_EQ(usb.claim_interface(cam, 1).error().code, Code::NOT_FOUND);
  EXPECT_EQ(*usb.kernel_driver_active(cam, 0), true);
  EXPECT_EQ(usb.claim_interface(cam, 0).error().code, Code::BUSY);  // gspca holds it
  ASSERT_TRUE(usb.detach_kernel_driver(cam, 0));
  EXPECT_EQ(*usb.kernel_driver_active(cam, 0), false);
  EXPECT_EQ(usb.detach_kernel_driver(cam, 0).error().code, Code::NOT_FOUND);
  Collector c;
  EXPECT_EQ(usb.start_iso(cam, 0x82, {}, c.callback()).error().code, Code::NOT_FOUND);  // unclaimed
  ASSERT_TRUE(usb.claim_interface(cam, 0));
  EXPECT_EQ(usb.claim_interface(cam, 0).error().code, Code::BUSY);
  EXPECT_EQ(usb.claim_interface(cam2, 0).error().code, Code::BUSY);
  EXPECT_EQ(usb.attach_kernel_driver(cam, 0).error().code, Code::BUSY);
  EXPECT_EQ(*usb.max_iso_packet_size(cam, 0x81), 1920U);
  EXPECT_EQ(*usb.max_iso_packet_size(cam, 0x82), 1920U);
  EXPECT_EQ(usb.max_iso_packet_size(cam, 0x83).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.start_iso(cam, 0x02, {}, c.callback()).error().code, Code::INVALID_PARAM);
  EXPECT_EQ(usb.start_iso(cam, 0x82, {0, 16, 1920}, c.callback()).error().code,
            Code::INVALID_PARAM);
  EXPECT_EQ(usb.start_iso(cam, 0x82, {}, nullptr).error().code, Code::INVALID_PARAM);
  EXPECT_EQ(usb.start_iso(cam, 0x83, {}, c.callback()).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.stop_iso(cam, 0x82).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.iso_stats(cam, 0x82).error().code, Code::NOT_FOUND);
  ASSERT_TRUE(usb.start_iso(cam, 0x82, {}, c.callback()));
  EXPECT_EQ(usb.start_iso(cam, 0x82, {}, c.callback()).error().code, Code::BUSY);
  EXPECT_EQ(usb.release_interface(cam, 0).error().code, Code::BUSY);
  EXPECT_EQ(usb.iso_stats(cam, 0x82)->transfers_in_flight, 16U);
  EXPECT_TRUE(usb.stop_iso(cam, 0x82));
  EXPECT_EQ(usb.handle_events(UsbTimeout{-1}).error().code, Code::INVALID_PARAM);
  std::vector<std::byte> big(65536);
  EXPECT_EQ(usb.control(cam, {0x40, 0, 0, 0}, big, TIMEOUT_500MS).error().code,
            Code::INVALID_PARAM);
  EXPECT_EQ(usb.bulk(cam, 0x81, big, TIMEOUT_500MS).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.interrupt(cam, 0x81, big, TIMEOUT_500MS).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.clear_halt(cam, 0x83).error().code, Code::NOT_FOUND);
  EXPECT_TRUE(usb.clear_halt(cam, 0x82));
  EXPECT_TRUE(usb.reset_device(cam));
  // Closing releases the claim and re-attaches the kernel driver it detached.
  usb.close(*cam_result);
  EXPECT_EQ(usb.claim_interface(*cam_result, 0).error().code, Code::NOT_OPEN);
  EXPECT_EQ(*usb.kernel_driver_active(cam2, 0), true);
  EXPECT_TRUE(usb.attach_kernel_driver(cam2, 0).error().code == Code::BUSY);
}

TEST(SimKinect, GmRoundTripEchoesTagAndKeepsARegisterFile) {
  Rig rig;
  std::vector<std::uint8_t> reply;
  ASSERT_EQ(*gm_read(rig.usb, rig.cam, reply), 0U);  // nothing pending: not ready
  reply = gm_exchange(rig.usb, rig.cam, 0x03, 0x1234, {0x15, 0x1E});
  ASSERT_EQ(reply.size(), 10U);
  EXPECT_EQ(reply[0], 0x52);
  EXPECT_EQ(reply[1], 0x42);
  EXPECT_EQ(le16(reply, 2), 1U);  // one word of payload
  EXPECT_EQ(le16(reply, 4), 0x03U);
  EXPECT_EQ(le16(reply, 6), 0x1234U);
  EXPECT_EQ(le16(reply, 8), 0U);
  reply = gm_exchange(rig.usb, rig.cam, 0x02, 0x1235, {0x15});
  ASSERT_EQ(reply.size(), 12U);
  EXPECT_EQ(le16(reply, 6), 0x1235U);
  EXPECT_EQ(le16(reply, 8), 0U);
  EXPECT_EQ(le16(reply, 10), 0x1EU);
  EXPECT_EQ(*rig.device().reg(0x15), 0x1E);
  ASSERT_EQ(rig.device().register_writes().size(), 1U);
  EXPECT_EQ(rig.device().register_writes()[0],
            (std::pair<std::uint16_t, std::uint16_t>{0x15, 0x1E}));
  reply = gm_exchange(rig.usb, rig.cam, 0x77, 9, {});  // unknown opcode: nonzero status
  ASSERT_EQ(reply.size(), 10U);
  EXPECT_NE(le16(reply, 8), 0U);
  std::vector<std::byte> bad(8, std::byte{0});  // no "GM" magic
  EXPECT_EQ(rig.usb.control(rig.cam, {0x40, 0, 0, 0}, bad, TIMEOUT_500MS).error().code, Code::PIPE);
  EXPECT_EQ(*gm_read(rig.usb, rig.cam, reply), 0U);
}

TEST(SimKinect, FixedAndAlgorithmParamsHaveTheDocumentedLayout) {
  for (const KinectModel model : {KinectModel::K1414, KinectModel::K1473}) {
    Rig rig(cheap_config(model));
    const auto reply = gm_exchange(rig.usb, rig.cam, 0x04, 1, {0, 0, 0, 0, 0});
    const std::size_t expected = model == KinectModel::K1414 ? 322 : 334;
    ASSERT_EQ(reply.size(), 8 + expected);
    EXPECT_EQ(le16(reply, 2) * 2U, expected);
    EXPECT_EQ(le16(reply, 8), 0U);
    const auto f32 = [&](std::size_t at) {
      const std::uint32_t u = reply[8 + at] | (reply[9 + at] << 8) | (reply[10 + at] << 16) |
                              (static_cast<std::uint32_t>(reply[11 + at]) << 24);
      return std::bit_cast<float>(u);
    };
    EXPECT_FLOAT_EQ(f32(94), 7.5F);
    EXPECT_FLOAT_EQ(f32(98), 2.3F);
    EXPECT_FLOAT_EQ(f32(102), 120.0F);
    EXPECT_FLOAT_EQ(f32(106), 0.1042F);
  }
  Rig rig;
  EXPECT_EQ(gm_exchange(rig.usb, rig.cam, 0x16, 1, {0x41, 0, 1, 30, 0}).size(), 16U);
  EXPECT_EQ(gm_exchange(rig.usb, rig.cam, 0x16, 2, {0x40, 0, 1, 30, 0}).size(), 8U + 118U);
  const auto shift = gm_exchange(rig.usb, rig.cam, 0x16, 3, {0x00, 0, 1, 30, 0});
  ASSERT_EQ(shift.size(), 12U);
  EXPECT_EQ(le16(shift, 10), 200U);
  EXPECT_NE(le16(gm_exchange(rig.usb, rig.cam, 0x16, 4, {0x33, 0, 1, 30, 0}), 8), 0U);
}

TEST(SimKinect, JunkAndEmptyRepliesComeBeforeTheRealOne) {
  Rig rig;
  SimKinectFaults f;
  f.junk_replies = 2;
  f.empty_replies = 3;
  rig.device().set_faults(f);
  ASSERT_TRUE(gm_send(rig.usb, rig.cam, 0x02, 7, {0x06}));
  std::vector<std::uint8_t> reply;
  const std::size_t expected[] = {512, 512, 0, 0, 0, 12, 0};
  for (const std::size_t n : expected) EXPECT_EQ(*gm_read(rig.usb, rig.cam, reply), n);
}

TEST(SimKinect, WrongTagAndWrongMagicAreOneShot) {
  Rig rig;
  SimKinectFaults f;
  f.wrong_tag_once = true;
  rig.device().set_faults(f);
  EXPECT_EQ(le16(gm_exchange(rig.usb, rig.cam, 0x02, 5, {0x06}), 6), 6U);
  EXPECT_EQ(le16(gm_exchange(rig.usb, rig.cam, 0x02, 5, {0x06}), 6), 5U);
  f.wrong_tag_once = false;
  f.wrong_magic_once = true;
  rig.device().set_faults(f);
  EXPECT_NE(gm_exchange(rig.usb, rig.cam, 0x02, 6, {0x06})[1], 0x42);
  EXPECT_EQ(gm_exchange(rig.usb, rig.cam, 0x02, 6, {0x06})[1], 0x42);
}

TEST(SimKinect, StalledControlTimesOutAfterItsTimeout) {
  Rig rig;
  SimKinectFaults f;
  f.control_stalls = 1;
  rig.device().set_faults(f);
  const std::int64_t t0 = rig.usb.clock().now_ns();
  EXPECT_EQ(gm_send(rig.usb, rig.cam, 0x03, 0, {0x15, 1}).error().code, Code::TIMEOUT);
  EXPECT_EQ(rig.usb.clock().now_ns() - t0, 500'000'000);
  EXPECT_FALSE(rig.device().reg(0x15).has_value());  // the stalled request did nothing
  write_reg(rig.usb, rig.cam, rig.tag, 0x15, 1);     // the next one works
  // Every control transfer takes the configured latency.
  const std::int64_t t1 = rig.usb.clock().now_ns();
  std::vector<std::uint8_t> reply;
  ASSERT_TRUE(gm_read(rig.usb, rig.cam, reply));
  EXPECT_EQ(rig.usb.clock().now_ns() - t1, 50'000);
}

struct MotorState {
  int x, y, z, tilt_half_deg, status;
};

MotorState read_motor(SimUsbTransport& usb, const UsbDeviceHandle& motor) {
  std::vector<std::byte> b(10);
  EXPECT_EQ(*usb.control(motor, {0xC0, 0x32, 0, 0}, b, TIMEOUT_500MS), 10U);
  const auto be = [&](std::size_t at) {
    return static_cast<int>(static_cast<std::int16_t>((std::to_integer<unsigned>(b[at]) << 8) |
                                                      std::to_integer<unsigned>(b[at + 1])));
  };
  return {be(2), be(4), be(6), static_cast<std::int8_t>(std::to_integer<unsigned>(b[8])),
          std::to_integer<int>(b[9])};
}

TEST(SimKinect, MotorSlewsToTheCommandedTiltAndTheAccelerometerSeesGravity) {
  SimUsbTransport usb;
  usb.add_kinect(cheap_config());
  auto motor_result = usb.open(usb.enumerate(0x045E, 0x02B0)->front());
  ASSERT_TRUE(motor_result);
  const UsbDeviceHandle& motor = *motor_result;
  EXPECT_EQ(*usb.kernel_driver_active(motor, 0), false);
  ASSERT_TRUE(usb.claim_interface(motor, 0));
  ASSERT_TRUE(usb.control(motor, {0x40, 0x31, 40, 0}, {}, TIMEOUT_500MS));  // +20 degrees
  ASSERT_TRUE(usb.control(motor, {0x40, 0x06, 1, 0}, {}, TIMEOUT_500MS));   // green
  EXPECT_EQ(usb.kinect(0).led(), 1);
  EXPECT_EQ(usb.control(motor, {0x40, 0x06, 9, 0}, {}, TIMEOUT_500MS).error().code, Code::PIPE);
  EXPECT_EQ(read_motor(usb, motor).status, 4);  // moving
  usb.run_for(std::chrono::milliseconds(500));  // 15 deg/s: about 7.5 degrees so far
  const MotorState half = read_motor(usb, motor);
  EXPECT_EQ(half.status, 4);
  EXPECT_NEAR(half.tilt_half_deg, 15, 1);
  usb.run_for(std::chrono::seconds(1));
  const MotorState done = read_motor(usb, motor);
  EXPECT_EQ(done.status, 0);
  EXPECT_EQ(done.tilt_half_deg, 40);
  EXPECT_NEAR(std::sqrt(double(done.x * done.x + done.y * done.y + done.z * done.z)), 819.0, 1.5);
  EXPECT_NEAR(std::atan2(done.z, done.y) * 180.0 / 3.14159265358979, 20.0, 0.2);
  // Past +-31 degrees the target is clamped; once there the status says "at limit".
  ASSERT_TRUE(
      usb.control(motor, {0x40, 0x31, static_cast<std::uint16_t>(-100), 0}, {}, TIMEOUT_500MS));
  usb.run_for(std::chrono::seconds(4));
  const MotorState limit = read_motor(usb, motor);
  EXPECT_EQ(limit.tilt_half_deg, -62);
  EXPECT_EQ(limit.status, 1);
  EXPECT_NEAR(std::atan2(limit.z, limit.y) * 180.0 / 3.14159265358979, -31.0, 0.2);
}

}  // namespace
}  // namespace orthoflow::simulation::test
