// The Kinect v1 control protocol as pure functions (USB_TESTING.md 3.2): command framing, the
// reply validation matrix, the golden register scripts, model detection, the calibration parsers
// and the depth tables against the formulas of KINECT_V1.md 8.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <vector>

#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/kinect/kinect_protocol.hpp"

namespace orthoflow::drivers::kinect {
namespace {

std::vector<std::byte> bytes(std::initializer_list<int> values) {
  std::vector<std::byte> out;
  for (int v : values) out.push_back(static_cast<std::byte>(v));
  return out;
}

std::vector<std::byte> reply(std::uint16_t opcode, std::uint16_t tag,
                             const std::vector<std::byte>& payload) {
  std::vector<std::byte> out(HEADER_BYTES + payload.size());
  out[0] = std::byte{0x52};
  out[1] = std::byte{0x42};
  store_le16(out, 2, static_cast<std::uint16_t>(payload.size() / 2));
  store_le16(out, 4, opcode);
  store_le16(out, 6, tag);
  std::memcpy(out.data() + HEADER_BYTES, payload.data(), payload.size());
  return out;
}

TEST(KinectCommand, FramesMagicLengthInWordsOpcodeAndTag) {
  const auto payload = bytes({0x06, 0x00, 0x02, 0x00});
  const auto frame = encode_command(0x03, 0x1234, payload);
  ASSERT_TRUE(frame.has_value());
  const auto v = frame->view();
  EXPECT_EQ(v.size(), 12U);
  EXPECT_EQ(std::vector<std::byte>(v.begin(), v.end()),
            bytes({0x47, 0x4D, 0x02, 0x00, 0x03, 0x00, 0x34, 0x12, 0x06, 0x00, 0x02, 0x00}));
}

TEST(KinectCommand, RefusesOddAndOverlongPayloads) {
  EXPECT_FALSE(encode_command(0x03, 0, bytes({1, 2, 3})).has_value());
  std::vector<std::byte> longest(MAX_COMMAND_PAYLOAD), too_long(MAX_COMMAND_PAYLOAD + 2);
  EXPECT_TRUE(encode_command(0x03, 0, longest).has_value());
  EXPECT_FALSE(encode_command(0x03, 0, too_long).has_value());
  EXPECT_TRUE(encode_command(0x03, 0, {}).has_value());
}

TEST(KinectReply, ValidationMatrixInLibfreenectsOrder) {
  const auto ok = reply(0x03, 7, bytes({0, 0}));
  const Reply good = check_reply(ok, 0x03, 7);
  EXPECT_EQ(good.check, ReplyCheck::OK);
  EXPECT_EQ(good.payload.size(), 2U);

  EXPECT_EQ(check_reply({}, 0x03, 7).check, ReplyCheck::NOT_READY);
  std::vector<std::byte> junk(512, std::byte{0xAB});  // the xHCI quirk
  EXPECT_EQ(check_reply(junk, 0x03, 7).check, ReplyCheck::NOT_READY);
  EXPECT_EQ(check_reply(std::span(ok).first(7), 0x03, 7).check, ReplyCheck::TOO_SHORT);
  auto magic = ok;
  magic[1] = std::byte{0x43};
  EXPECT_EQ(check_reply(magic, 0x03, 7).check, ReplyCheck::BAD_MAGIC);
  EXPECT_EQ(check_reply(ok, 0x02, 7).check, ReplyCheck::WRONG_OPCODE);
  EXPECT_EQ(check_reply(ok, 0x03, 8).check, ReplyCheck::WRONG_TAG);
  auto length = ok;
  store_le16(length, 2, 2);  // claims 4 payload bytes, carries 2
  EXPECT_EQ(check_reply(length, 0x03, 7).check, ReplyCheck::BAD_LENGTH);
  // Magic is checked before the opcode: a reply wrong in both is BAD_MAGIC.
  EXPECT_EQ(check_reply(magic, 0x02, 8).check, ReplyCheck::BAD_MAGIC);
}

TEST(KinectScripts, DepthElevenBitIsTheDocumentedSequence) {
  const RegisterScript s = depth_start_script(DepthFormat::BITS_11);
  const std::vector<std::pair<int, int>> want = {{0x105, 0},   {6, 0}, {0x12, 3}, {0x13, 1},
                                                 {0x14, 0x1E}, {6, 2}, {0x17, 0}};
  ASSERT_EQ(s.size(), want.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s[i].reg, want[i].first) << i;
    EXPECT_EQ(s[i].value, want[i].second) << i;
    EXPECT_EQ(s[i].wait_ms, 0) << i;
  }
  EXPECT_EQ(depth_start_script(DepthFormat::BITS_10)[2].value, 2);
  ASSERT_EQ(depth_stop_script().size(), 1U);
  EXPECT_EQ(depth_stop_script()[0].reg, 6);
  EXPECT_EQ(depth_stop_script()[0].value, 0);
}

TEST(KinectScripts, VideoModesAndQuirks) {
  auto regs = [](RegisterScript s) {
    std::vector<std::pair<int, int>> out;
    for (const auto& w : s) out.emplace_back(w.reg, w.value);
    return out;
  };
  using V = std::vector<std::pair<int, int>>;
  EXPECT_EQ(regs(video_start_script(VideoFormat::BAYER)),
            (V{{0x0C, 0}, {0x0D, 1}, {0x0E, 0x1E}, {0x05, 1}, {0x47, 0}}));
  EXPECT_EQ(regs(video_start_script(VideoFormat::UYVY)),
            (V{{0x0C, 5}, {0x0D, 1}, {0x0E, 0x0F}, {0x05, 1}, {0x47, 0}}));
  EXPECT_EQ(regs(video_start_script(VideoFormat::IR_10BIT)),
            (V{{0x19, 0}, {0x1A, 1}, {0x1B, 0x1E}, {0x105, 0}, {0x05, 3}, {0x48, 0}}));
  // 1280x1024 IR needs the dummy depth start/stop first.
  const V high = regs(video_start_script(VideoFormat::IR_HIGH));
  EXPECT_EQ(V(high.begin(), high.begin() + 4), (V{{0x13, 1}, {0x14, 0x1E}, {0x06, 2}, {0x06, 0}}));
  EXPECT_EQ(high[5], (std::pair<int, int>{0x1A, 2}));
  EXPECT_EQ(regs(video_stop_script()), (V{{0x05, 0}}));
  const RegisterScript near_on = near_mode_script(true);
  ASSERT_EQ(near_on.size(), 2U);
  EXPECT_EQ(near_on[0].reg, 0x15);
  EXPECT_EQ(near_on[0].value, 7);
  EXPECT_EQ(near_on[1].reg, 0x2EF);
  EXPECT_EQ(near_on[1].wait_ms, 100);
  EXPECT_EQ(near_mode_script(false)[1].value, 0x190);
}

TEST(KinectModel, DetectedFromProductAndBcdDevice) {
  UsbDeviceInfo d;
  d.vendor = VENDOR_MICROSOFT;
  d.product = PID_CAMERA;
  d.bcd_device = 0x010B;
  EXPECT_EQ(detect_model(d), Model::K1414);
  d.bcd_device = 0x010F;
  EXPECT_EQ(detect_model(d), Model::K1473);
  d.product = PID_CAMERA_K4W;
  EXPECT_EQ(detect_model(d), Model::K4W);
  d.product = PID_MOTOR;
  EXPECT_FALSE(detect_model(d).has_value());
  d.vendor = 0x1234;
  d.product = PID_CAMERA;
  EXPECT_FALSE(detect_model(d).has_value());
}

std::vector<std::byte> fixed_params(std::size_t size, float emitter, float rcmos, float dist,
                                    float pix) {
  std::vector<std::byte> p(size);
  const float values[4] = {emitter, rcmos, dist, pix};
  std::memcpy(p.data() + 94, values, sizeof values);  // little-endian hosts (x86, aarch64)
  return p;
}

TEST(KinectCalibration, FixedParamsAtOffset94WithTheRcmosOverride) {
  ZeroPlane zp;
  float reported = 0;
  ASSERT_EQ(
      parse_fixed_params(fixed_params(322, 7.5F, 2.3F, 120.F, 0.1042F), Model::K1414, zp, reported),
      ParseCheck::OK);
  EXPECT_FLOAT_EQ(zp.dcmos_emitter_dist_cm, 7.5F);
  EXPECT_FLOAT_EQ(zp.dcmos_rcmos_dist_cm, 2.4F);
  EXPECT_FLOAT_EQ(reported, 2.3F);
  EXPECT_FLOAT_EQ(zp.reference_distance_mm, 120.F);
  EXPECT_FLOAT_EQ(zp.reference_pixel_size_mm, 0.1042F);
  EXPECT_EQ(
      parse_fixed_params(fixed_params(334, 7.5F, 2.3F, 120.F, 0.1042F), Model::K1473, zp, reported),
      ParseCheck::OK);
  // The size is model-specific.
  EXPECT_EQ(
      parse_fixed_params(fixed_params(334, 7.5F, 2.3F, 120.F, 0.1042F), Model::K1414, zp, reported),
      ParseCheck::WRONG_SIZE);
  auto status = fixed_params(322, 7.5F, 2.3F, 120.F, 0.1042F);
  status[0] = std::byte{1};
  EXPECT_EQ(parse_fixed_params(status, Model::K1414, zp, reported), ParseCheck::DEVICE_STATUS);
  EXPECT_EQ(
      parse_fixed_params(fixed_params(322, NAN, 2.3F, 120.F, 0.1042F), Model::K1414, zp, reported),
      ParseCheck::NOT_FINITE);
  EXPECT_EQ(
      parse_fixed_params(fixed_params(322, 7.5F, 2.3F, 120.F, 0.0F), Model::K1414, zp, reported),
      ParseCheck::OUT_OF_RANGE);
}

TEST(KinectCalibration, PadRegInfoAndConstShift) {
  PadInfo pad;
  EXPECT_EQ(parse_pad_info(bytes({0, 0, 0, 0, 7, 0, 1, 0}), pad), ParseCheck::OK);
  EXPECT_EQ(pad.end_lines, 7);
  EXPECT_EQ(pad.cropping_lines, 1);
  EXPECT_EQ(parse_pad_info(bytes({0, 0, 0, 0}), pad), ParseCheck::WRONG_SIZE);
  RegInfo reg;
  std::vector<std::byte> words(118);
  const std::int32_t minus_two = -2;
  std::memcpy(words.data() + 2 + 4 * 28, &minus_two, 4);
  EXPECT_EQ(parse_reg_info(words, reg), ParseCheck::OK);
  EXPECT_EQ(reg.words[28], -2);
  EXPECT_STREQ(reg_info_name(28), "dydydy_start");
  EXPECT_STREQ(reg_info_name(0), "dx_center");
  std::uint16_t shift = 0;
  EXPECT_EQ(parse_const_shift(bytes({0, 0, 0xC8, 0}), shift), ParseCheck::OK);
  EXPECT_EQ(shift, 200);
  EXPECT_EQ(parse_const_shift(bytes({0, 0, 0, 0}), shift), ParseCheck::OUT_OF_RANGE);
  EXPECT_EQ(parse_const_shift(bytes({1, 0, 0xC8, 0}), shift), ParseCheck::DEVICE_STATUS);
}

TEST(KinectDepth, TableFollowsTheDeviceFormulaAndNeverWraps) {
  Calibration cal;  // 7.5 cm, 120 mm, 0.1042 mm, shift 200: the brief's typical device
  // KINECT_V1.md 8.1 table, "registration formula" column: 500 -> 586, 800 -> 1194, 1000 -> 3864.
  EXPECT_NEAR(raw_to_mm(500, cal), 586, 1.0);
  EXPECT_NEAR(raw_to_mm(700, cal), 887, 1.0);
  EXPECT_NEAR(raw_to_mm(800, cal), 1194, 1.0);
  EXPECT_NEAR(raw_to_mm(900, cal), 1824, 1.0);
  EXPECT_NEAR(raw_to_mm(1000, cal), 3864, 1.0);
  const DepthTableMm mm = make_depth_table_mm(cal);
  EXPECT_EQ(mm[2047], 0);
  EXPECT_EQ(mm[800], 1193);  // truncated, as libfreenect's DEPTH_MM
  // Monotonic up to the 10 m cut, then 0 past the pole: never a wrapped or negative value.
  std::uint16_t previous = 0;
  bool cut = false;
  for (std::size_t raw = 0; raw < 2047; ++raw) {
    if (mm[raw] == 0) {
      cut = raw > 1000;
      continue;
    }
    EXPECT_FALSE(cut) << "depth after the cut at raw " << raw;
    EXPECT_GE(mm[raw], previous) << raw;
    EXPECT_LE(mm[raw], 10000) << raw;
    previous = mm[raw];
  }
  EXPECT_TRUE(cut);
  std::array<float, kernels::DISPARITY_TABLE_SIZE> m{};
  make_depth_table_m(cal, m);
  EXPECT_NEAR(m[800], 1.1938F, 1e-4F);
  EXPECT_EQ(m[2047], 0.0F);
  const kernels::DepthCamera cam = depth_camera(cal);
  EXPECT_NEAR(cam.fx, 575.816F, 1e-2F);
  EXPECT_EQ(cam.fx, cam.fy);
}

TEST(KinectDepth, DepthToRawAndBackStaysWithinOneDisparityStep) {
  // The inverse the simulator sends raw frames with: depth -> raw -> depth lands on the nearest
  // level, so within one step of the levels around it, over the whole usable range.
  Calibration cal;
  const DisparityModel model = disparity_model(cal);
  for (double mm = 500.0; mm <= 8000.0; mm *= 1.0007) {
    const std::uint16_t raw = mm_to_raw(mm, model);
    ASSERT_GT(raw, 0) << mm;
    ASSERT_LT(raw, RAW_NO_READING - 1) << mm;
    const double back = raw_to_mm(raw, cal);
    const double step = raw_to_mm(static_cast<std::uint16_t>(raw + 1), cal) - back;
    EXPECT_GT(step, 0.0) << mm;
    EXPECT_LE(std::abs(back - mm), step) << mm << " mm -> raw " << raw << " -> " << back;
  }
  // The continuous inverse undoes the formula; no depth gives "no reading" or a wrapped value.
  for (double raw = 300.0; raw < 1050.0; raw += 3.5) {
    EXPECT_NEAR(mm_to_disparity(disparity_to_mm(raw, model), model), raw, 1e-6) << raw;
  }
  EXPECT_EQ(mm_to_raw(0.0, model), RAW_NO_READING);
  EXPECT_EQ(mm_to_raw(-5.0, model), RAW_NO_READING);
  EXPECT_EQ(mm_to_raw(std::nan(""), model), RAW_NO_READING);
  EXPECT_EQ(mm_to_raw(1.0, model), 0);                      // nearer than raw 0: clamped
  EXPECT_EQ(mm_to_raw(1e9, model), 1089);                   // at the pole
  EXPECT_EQ(disparity_to_mm(2047.0, model), 0.0);           // no reading
  EXPECT_GT(disparity_to_mm(1085.0, model), DEPTH_MAX_MM);  // the formula has no 10 m cut...
  EXPECT_EQ(raw_to_mm(1085, cal), 0.0);                     // ...the tables do
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
