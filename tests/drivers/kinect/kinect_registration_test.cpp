// Depth-to-colour registration (drivers/kinect/kinect_registration.hpp): tables, bounds, z-buffer
// and refused calibrations. The comparison with libfreenect's FREENECT_DEPTH_REGISTERED is in
// tests/support/sim_libusb/freenect_check_test.cpp.
#include "drivers/kinect/kinect_registration.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace orthoflow::drivers::kinect {
namespace {

// Registration words as a real Kinect v1 reports them (a published dump, in reg_info_name order):
// the *_start words are packed two's-complement fields (21 and 27 bits), which only the 32-bit
// scaling turns into the small negative numbers they mean.
constexpr std::array<std::int32_t, 29> TYPICAL_WORDS = {
    2048330528, 1964,      56,        -26,       600,       6161, -13,       2825,    684,      5,
    6434,       10062,     130801,    0,         0,         170,  136,       2095986, 890,      763,
    2096378,    134215474, 134217093, 134216989, 134216925, 0,    134216984, 0,       134214659};

Calibration typical() {
  Calibration cal;
  for (std::size_t i = 0; i < cal.reg.words.size(); ++i) cal.reg.words[i] = TYPICAL_WORDS[i];
  return cal;
}

Registration make(const Calibration& cal) {
  auto maybe = Registration::create(cal);
  EXPECT_TRUE(maybe.has_value());
  return std::move(maybe).value();
}

// The raw disparity whose millimetre value is closest to @p mm.
std::uint16_t raw_for_mm(const Registration& reg, std::uint16_t mm) {
  std::uint16_t best = 0;
  int best_diff = std::numeric_limits<int>::max();
  for (std::uint16_t raw = 0; raw < 2047; ++raw) {
    const int d = std::abs(static_cast<int>(reg.depth_mm(raw)) - mm);
    if (reg.depth_mm(raw) != 0 && d < best_diff) {
      best = raw;
      best_diff = d;
    }
  }
  return best;
}

TEST(KinectRegistration, WordIndicesFollowTheDeviceOrder) {
  // The implementation addresses the words by these positions.
  const std::array<std::pair<std::size_t, const char*>, 20> used = {{
      {1, "ax"},
      {2, "bx"},
      {3, "cx"},
      {4, "dx"},
      {5, "dx_start"},
      {6, "ay"},
      {7, "by"},
      {8, "cy"},
      {9, "dy"},
      {10, "dy_start"},
      {17, "dxdx_start"},
      {18, "dxdy_start"},
      {19, "dydx_start"},
      {20, "dydy_start"},
      {21, "dxdxdx_start"},
      {22, "dydxdx_start"},
      {23, "dxdxdy_start"},
      {24, "dydxdy_start"},
      {26, "dydydx_start"},
      {28, "dydydy_start"},
  }};
  for (const auto& [index, name] : used) EXPECT_STREQ(reg_info_name(index), name) << index;
}

TEST(KinectRegistration, MillimetresAreThoseOfTheDepthTable) {
  const Calibration cal = typical();
  const Registration reg = make(cal);
  const DepthTableMm table = make_depth_table_mm(cal);
  for (std::size_t raw = 0; raw < table.size(); ++raw) {
    const std::uint16_t want = table[raw] >= REGISTERED_MAX_MM ? 0 : table[raw];
    EXPECT_EQ(reg.depth_mm(static_cast<std::uint16_t>(raw)), want) << raw;
  }
  EXPECT_EQ(reg.depth_mm(RAW_NO_READING), 0);
  EXPECT_EQ(reg.depth_mm(2048), 0);
  EXPECT_EQ(reg.depth_mm(65535), 0);
}

TEST(KinectRegistration, ShiftGrowsWithDepthTowardTheBaseline) {
  const Registration reg = make(typical());
  EXPECT_EQ(reg.shift_fixed(0), 0);
  EXPECT_EQ(reg.shift_fixed(REGISTERED_MAX_MM), 0);
  for (std::uint16_t mm = 300; mm + 1 < REGISTERED_MAX_MM; ++mm)
    ASSERT_LE(reg.shift_fixed(mm), reg.shift_fixed(static_cast<std::uint16_t>(mm + 1))) << mm;
  // At the 1200 mm reference plane only the 0.375 px offset remains; far away it approaches the
  // 2.4 cm baseline in pixels (2.4 x 10 / (0.1042 x 2 x 10) = 11.52 px).
  EXPECT_NEAR(reg.shift_fixed(1200), 0.375 * SUBPIXELS, 2.0);
  const double baseline_px = 2.4 / (0.1042 * 2.0);
  EXPECT_NEAR(reg.shift_fixed(9999) / double{SUBPIXELS},
              baseline_px * (1.0 - 1200.0 / 9999.0) + 0.375, 0.01);
  EXPECT_LT(reg.shift_fixed(500), 0);
  EXPECT_GT(reg.shift_fixed(500), -32 * SUBPIXELS);  // the nearest readings stay within 32 px
}

TEST(KinectRegistration, OutputIsFullSizeAndNoReadingStaysZero) {
  const Registration reg = make(typical());
  std::vector<std::uint16_t> raw(REGISTERED_PIXELS, RAW_NO_READING);
  std::vector<std::uint16_t> out(REGISTERED_PIXELS, 1234);
  reg.register_depth(raw, out);
  EXPECT_EQ(out.size(), REGISTERED_PIXELS);
  for (const std::uint16_t v : out) ASSERT_EQ(v, 0);
  std::fill(raw.begin(), raw.end(), std::uint16_t{0xFFFF});  // out-of-range raw: no reading
  reg.register_depth(raw, out);
  for (const std::uint16_t v : out) ASSERT_EQ(v, 0);
}

TEST(KinectRegistration, AFlatWallKeepsMostOfItsPixelsAndItsDepth) {
  const Registration reg = make(typical());
  const std::uint16_t raw_value = raw_for_mm(reg, 1500);
  const std::uint16_t mm = reg.depth_mm(raw_value);
  std::vector<std::uint16_t> raw(REGISTERED_PIXELS, raw_value);
  std::vector<std::uint16_t> out(REGISTERED_PIXELS);
  reg.register_depth(raw, out);
  std::size_t valid = 0;
  for (const std::uint16_t v : out) {
    ASSERT_TRUE(v == 0 || v == mm);
    valid += v != 0 ? 1 : 0;
  }
  EXPECT_GT(valid, REGISTERED_PIXELS * 8 / 10);
}

TEST(KinectRegistration, TheNearestDepthWinsATarget) {
  const Registration reg = make(typical());
  const std::uint16_t near_raw = raw_for_mm(reg, 800);
  const std::uint16_t far_raw = raw_for_mm(reg, 3000);
  const std::uint16_t near_mm = reg.depth_mm(near_raw);
  // Find two source pixels in one row that land on one target at these two depths (the far one
  // shifts about 12 px further right, so it starts to the left of the near one).
  for (std::size_t y = 100; y < 380; ++y) {
    for (std::size_t x = 100; x < 540; ++x) {
      const auto t_near = reg.target_index(x, y, near_mm);
      for (std::size_t x2 = x - 40; x2 < x && t_near; ++x2) {
        if (reg.target_index(x2, y, reg.depth_mm(far_raw)) != t_near) continue;
        std::vector<std::uint16_t> raw(REGISTERED_PIXELS, RAW_NO_READING);
        std::vector<std::uint16_t> out(REGISTERED_PIXELS);
        raw[y * REGISTERED_WIDTH + x] = near_raw;
        raw[y * REGISTERED_WIDTH + x2] = far_raw;
        reg.register_depth(raw, out);
        EXPECT_EQ(out[*t_near], near_mm);
        return;
      }
    }
  }
  FAIL() << "no colliding pixels found";
}

TEST(KinectRegistration, PadStartLinesMoveTheImageUp) {
  Calibration cal = typical();
  const Registration plain = make(cal);
  cal.pad.start_lines = 1;  // 480 target pixels earlier (libfreenect's offset: rows x start_lines)
  const Registration padded = make(cal);
  const auto a = plain.target_index(320, 240, 1500);
  const auto b = padded.target_index(320, 240, 1500);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(*a - *b, REGISTERED_HEIGHT);
  cal.pad.start_lines = 65535;  // everything moves out: nothing written, nothing out of bounds
  const Registration gone = make(cal);
  std::vector<std::uint16_t> raw(REGISTERED_PIXELS, raw_for_mm(gone, 1500));
  std::vector<std::uint16_t> out(REGISTERED_PIXELS, 7);
  gone.register_depth(raw, out);
  for (const std::uint16_t v : out) ASSERT_EQ(v, 0);
}

TEST(KinectRegistration, ZeroAndExtremeWordsStayInBounds) {
  for (const std::int32_t word : {0, 1, -1, std::numeric_limits<std::int32_t>::max(),
                                  std::numeric_limits<std::int32_t>::min(), 0x00123456}) {
    Calibration cal;
    cal.reg.words.fill(word);
    const Registration reg = make(cal);
    std::vector<std::uint16_t> raw(REGISTERED_PIXELS);
    for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = static_cast<std::uint16_t>(i % 2048);
    std::vector<std::uint16_t> out(REGISTERED_PIXELS);
    reg.register_depth(raw, out);  // ASan/UBSan builds check the bounds and the arithmetic
    for (std::size_t x = 0; x < REGISTERED_WIDTH; x += 7) {
      const auto t = reg.target_index(x, 240, 1500);
      if (t) { EXPECT_LT(*t, REGISTERED_PIXELS); }
    }
  }
  Calibration zero;  // all-zero words: no displacement, one pixel of offset (x + 1, y + 1)
  const Registration reg = make(zero);
  const auto t = reg.target_index(10, 20, 1200);
  ASSERT_TRUE(t);
  EXPECT_EQ(*t / REGISTERED_WIDTH, 21U);
  EXPECT_FALSE(reg.target_index(10, 479, 1200));  // row 480 is outside
  EXPECT_FALSE(reg.target_index(640, 0, 1200));
  EXPECT_FALSE(reg.target_index(0, 0, 0));
}

TEST(KinectRegistration, ExtremeZeroPlanesAreClampedOrRefused) {
  Calibration cal = typical();
  cal.zero_plane.dcmos_rcmos_dist_cm = 1e30F;  // absurd baseline: shifts clamp, nothing lands
  const Registration wide = make(cal);
  std::vector<std::uint16_t> raw(REGISTERED_PIXELS, 700);
  std::vector<std::uint16_t> out(REGISTERED_PIXELS, 7);
  wide.register_depth(raw, out);
  for (std::size_t i = 0; i < out.size(); i += 97) ASSERT_EQ(out[i], 0) << i;

  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (const float bad : {nan, inf}) {
    Calibration c = typical();
    c.zero_plane.reference_pixel_size_mm = bad;
    auto r = Registration::create(c);
    ASSERT_FALSE(r.has_value());
    EXPECT_EQ(r.error(), Registration::Error::NOT_FINITE);
    EXPECT_STREQ(to_string(r.error()), "not_finite");
  }
  cal.zero_plane.dcmos_rcmos_dist_cm = 2.4F;
  // A denormal pixel size is accepted: every depth reads as the 1200 mm reference plane, where the
  // shift is the bare 0.375 px; the shifts elsewhere clamp.
  cal.zero_plane.reference_pixel_size_mm = 1e-45F;
  const Registration tiny = make(cal);
  tiny.register_depth(raw, out);
  for (const std::uint16_t v : out) ASSERT_TRUE(v == 0 || v == tiny.depth_mm(700)) << v;
  EXPECT_EQ(tiny.shift_fixed(1200), 96);
  EXPECT_EQ(tiny.shift_fixed(1199), -(1 << 24));
  for (const float bad : {0.0F, -0.1F}) {
    Calibration c = typical();
    c.zero_plane.reference_pixel_size_mm = bad;
    auto r = Registration::create(c);
    ASSERT_FALSE(r.has_value()) << bad;
    EXPECT_EQ(r.error(), Registration::Error::OUT_OF_RANGE);
    EXPECT_STREQ(to_string(r.error()), "out_of_range");
  }
  Calibration c = typical();
  c.zero_plane.reference_distance_mm = 0.0F;
  auto r = Registration::create(c);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error(), Registration::Error::OUT_OF_RANGE);
}

TEST(KinectRegistration, DeterministicAcrossRunsAndInstances) {
  const Registration a = make(typical());
  const Registration b = make(typical());
  std::vector<std::uint16_t> raw(REGISTERED_PIXELS);
  for (std::size_t i = 0; i < raw.size(); ++i)
    raw[i] = static_cast<std::uint16_t>(500 + (i * 7919) % 600);
  std::vector<std::uint16_t> out_a(REGISTERED_PIXELS);
  std::vector<std::uint16_t> out_a2(REGISTERED_PIXELS, 99);
  std::vector<std::uint16_t> out_b(REGISTERED_PIXELS);
  a.register_depth(raw, out_a);
  a.register_depth(raw, out_a2);
  b.register_depth(raw, out_b);
  EXPECT_EQ(out_a, out_a2);
  EXPECT_EQ(out_a, out_b);
}

TEST(KinectRegistrationDeathTest, WrongSizesAreBugs) {
  const Registration reg = make(typical());
  std::vector<std::uint16_t> raw(REGISTERED_PIXELS - 1);
  std::vector<std::uint16_t> out(REGISTERED_PIXELS);
  EXPECT_DEATH(reg.register_depth(raw, out), "640x480");
  std::vector<std::uint16_t> raw_ok(REGISTERED_PIXELS);
  std::vector<std::uint16_t> empty;
  EXPECT_DEATH(reg.register_depth(raw_ok, empty), "640x480");
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
