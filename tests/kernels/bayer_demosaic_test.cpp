// Kinect v1 GRBG demosaic (KINECT_V1.md 7.3): the scalar twin, the dispatched kernel and every
// compiled SIMD variant, for both output forms, against a per-pixel oracle written from the
// header's rule; hand-computed 2x2 and 4x4 images, flat colours, the GRBG phase of mosaic_grbg(),
// random and extreme mosaics around the SIMD widths and at 640x480, and inputs that sit right
// next to a protected page (an over-read faults even without ASan).
#include "kernels/bayer_demosaic.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <array>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "kernels/detail/bayer_demosaic_kernel.hpp"

namespace ok = orthoflow::kernels;
namespace od = orthoflow::kernels::detail;

namespace {

using Bytes = std::vector<std::uint8_t>;
using Words = std::vector<std::uint32_t>;
using Rgb24Fn = std::function<void(std::span<const std::uint8_t>, std::uint32_t, std::uint32_t,
                                   std::span<std::uint8_t>)>;
using PackedFn = std::function<void(std::span<const std::uint8_t>, std::uint32_t, std::uint32_t,
                                    std::span<std::uint32_t>)>;

struct Variant {
  std::string name;
  Rgb24Fn rgb24;
  PackedFn packed;
};

// Scalar twin, dispatched kernel, and each compiled architecture this CPU supports.
std::vector<Variant> variants() {
  std::vector<Variant> v;
  v.push_back({"scalar", ok::demosaic_grbg_scalar, ok::demosaic_grbg_packed_scalar});
  v.push_back({"dispatched", ok::demosaic_grbg, ok::demosaic_grbg_packed});
  ok::for_each_available_arch([&](auto arch) {
    v.push_back({decltype(arch)::name(),
                 [arch](auto b, auto w, auto h, auto o) {
                   od::DemosaicKernel<od::DemosaicForm::RGB24>{}(arch, b, w, h, o);
                 },
                 [arch](auto b, auto w, auto h, auto o) {
                   od::DemosaicKernel<od::DemosaicForm::PACKED>{}(arch, b, w, h, o);
                 }});
  });
  return v;
}

// The oracle, straight from the header: reflect-101 indices, then the interior rule.
int reflect(int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); }

Bytes oracle(const Bytes& bayer, int w, int h) {
  Bytes out(3 * bayer.size());
  auto at = [&](int y, int x) -> unsigned {
    return bayer.at(static_cast<std::size_t>(reflect(y, h) * w + reflect(x, w)));
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const unsigned c = at(y, x);
      const unsigned horiz = (at(y, x - 1) + at(y, x + 1) + 1) / 2;
      const unsigned vert = (at(y - 1, x) + at(y + 1, x) + 1) / 2;
      const unsigned cross = (at(y - 1, x) + at(y + 1, x) + at(y, x - 1) + at(y, x + 1) + 2) / 4;
      const unsigned diag =
          (at(y - 1, x - 1) + at(y - 1, x + 1) + at(y + 1, x - 1) + at(y + 1, x + 1) + 2) / 4;
      std::array<unsigned, 3> rgb{};
      if (y % 2 == 0 && x % 2 == 0) rgb = {horiz, c, vert};  // G on a G R row
      if (y % 2 == 0 && x % 2 == 1) rgb = {c, cross, diag};  // R
      if (y % 2 == 1 && x % 2 == 0) rgb = {diag, cross, c};  // B
      if (y % 2 == 1 && x % 2 == 1) rgb = {vert, c, horiz};  // G on a B G row
      for (int k = 0; k < 3; ++k) {
        out[3 * static_cast<std::size_t>(y * w + x) + static_cast<std::size_t>(k)] =
            static_cast<std::uint8_t>(rgb[static_cast<std::size_t>(k)]);
      }
    }
  }
  return out;
}

Words repack(const Bytes& rgb) {
  Words out(rgb.size() / 3);
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = 0xFF000000U | (std::uint32_t{rgb[3 * i]} << 16) |
             (std::uint32_t{rgb[3 * i + 1]} << 8) | rgb[3 * i + 2];
  }
  return out;
}

// Runs every variant (exactly sized outputs) and checks it against the oracle, both forms.
void expect_all_variants(const Bytes& bayer, std::uint32_t w, std::uint32_t h,
                         const std::string& what) {
  const Bytes want = oracle(bayer, static_cast<int>(w), static_cast<int>(h));
  const Words want_packed = repack(want);
  for (const Variant& v : variants()) {
    Bytes got(3 * bayer.size(), 0xEE);
    v.rgb24(bayer, w, h, got);
    EXPECT_EQ(got, want) << v.name << " " << what << " " << w << "x" << h;
    Words got_packed(bayer.size(), 0xEEEEEEEEU);
    v.packed(bayer, w, h, got_packed);
    EXPECT_EQ(got_packed, want_packed) << v.name << " packed " << what << " " << w << "x" << h;
  }
}

Bytes random_mosaic(std::uint32_t w, std::uint32_t h, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Bytes b(std::size_t{w} * h);
  for (auto& x : b) x = static_cast<std::uint8_t>(rng());
  return b;
}

TEST(BayerDemosaic, MosaicKeepsTheGrbgPhase) {
  constexpr std::uint32_t W = 6, H = 4;
  const std::array<std::array<std::uint8_t, 3>, 3> pure{{{255, 0, 0}, {0, 255, 0}, {0, 0, 255}}};
  for (std::size_t channel = 0; channel < 3; ++channel) {
    Bytes rgb(3 * W * H);
    for (std::size_t i = 0; i < W * H; ++i) {
      for (std::size_t k = 0; k < 3; ++k) rgb[3 * i + k] = pure[channel][k];
    }
    Bytes bayer(W * H, 0x77);
    ok::mosaic_grbg(rgb, W, H, bayer);
    for (std::uint32_t y = 0; y < H; ++y) {
      for (std::uint32_t x = 0; x < W; ++x) {
        const bool r_site = y % 2 == 0 && x % 2 == 1;  // row 0, odd columns
        const bool b_site = y % 2 == 1 && x % 2 == 0;  // row 1, even columns
        const bool g_site = !r_site && !b_site;
        const bool lit = channel == 0 ? r_site : (channel == 1 ? g_site : b_site);
        EXPECT_EQ(bayer[y * W + x], lit ? 255 : 0)
            << "channel " << channel << " at " << y << "," << x;
      }
    }
  }
  // Row 0 is G R G R, row 1 is B G B G.
  const Bytes rgb{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};  // 2x2: (1,2,3) (4,5,6) / (7,8,9) ...
  Bytes bayer(4);
  ok::mosaic_grbg(rgb, 2, 2, bayer);
  EXPECT_EQ(bayer, (Bytes{2, 4, 9, 11}));
}

TEST(BayerDemosaic, FlatColourSurvivesEverywhere) {
  const std::array<std::array<std::uint8_t, 3>, 5> colours{
      {{0, 0, 0}, {255, 255, 255}, {255, 0, 0}, {1, 2, 3}, {200, 100, 37}}};
  const std::array<std::array<std::uint32_t, 2>, 6> shapes{
      {{2, 2}, {4, 2}, {2, 4}, {34, 6}, {130, 4}, {640, 480}}};
  for (const auto& c : colours) {
    for (const auto& [w, h] : shapes) {
      Bytes rgb(3 * std::size_t{w} * h);
      for (std::size_t i = 0; i < std::size_t{w} * h; ++i) {
        for (std::size_t k = 0; k < 3; ++k) rgb[3 * i + k] = c[k];
      }
      Bytes bayer(std::size_t{w} * h);
      ok::mosaic_grbg(rgb, w, h, bayer);
      const std::uint32_t want_packed =
          0xFF000000U | (std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2];
      for (const Variant& v : variants()) {
        Bytes got(rgb.size(), 0xEE);
        v.rgb24(bayer, w, h, got);
        EXPECT_EQ(got, rgb) << v.name << " " << w << "x" << h;
        Words got_packed(bayer.size(), 0);
        v.packed(bayer, w, h, got_packed);
        EXPECT_EQ(got_packed, Words(bayer.size(), want_packed)) << v.name << " " << w << "x" << h;
      }
    }
  }
}

// G00 = 10, R01 = 200, B10 = 50, G11 = 31: every pixel sees the one R and the one B; the R and B
// pixels get G = (2*10 + 2*31 + 2) / 4 = 21 (the mean 20.5 rounds up).
TEST(BayerDemosaic, HandComputed2x2) {
  const Bytes bayer{10, 200, 50, 31};
  const Bytes want{200, 10, 50, 200, 21, 50,   // row 0: G, R
                   200, 21, 50, 200, 31, 50};  // row 1: B, G
  EXPECT_EQ(oracle(bayer, 2, 2), want);
  for (const Variant& v : variants()) {
    Bytes got(12, 0xEE);
    v.rgb24(bayer, 2, 2, got);
    EXPECT_EQ(got, want) << v.name;
    Words got_packed(4, 0);
    v.packed(bayer, 2, 2, got_packed);
    EXPECT_EQ(got_packed, (Words{0xFFC80A32U, 0xFFC81532U, 0xFFC81532U, 0xFFC81F32U})) << v.name;
  }
}

// Each pixel worked out by hand from the header's rule (row -1 = row 1, row 4 = row 2, column
// -1 = column 1, column 4 = column 2). For example (0,1), an R pixel on the top edge:
// G = (16 + 16 + 12 + 14 + 2) / 4 = 15, B = (40 + 60 + 40 + 60 + 2) / 4 = 50; (1,0), a B pixel on
// the left edge: G = (12 + 20 + 16 + 16 + 2) / 4 = 16, R = (200 + 200 + 220 + 220 + 2) / 4 = 210.
TEST(BayerDemosaic, HandComputed4x4) {
  const Bytes bayer{12, 200, 14,  180,                                     // G R G R
                    40, 16,  60,  18,                                      // B G B G
                    20, 220, 22,  240,                                     // G R G R
                    80, 24,  100, 26};                                     // B G B G
  const Bytes want{200, 12, 40, 200, 15, 50, 190, 14, 60,  180, 16, 60,    // row 0
                   210, 16, 40, 210, 16, 50, 210, 18, 60,  210, 18, 60,    // row 1
                   220, 20, 60, 220, 21, 70, 230, 22, 80,  240, 22, 80,    // row 2
                   220, 22, 80, 220, 24, 90, 230, 24, 100, 240, 26, 100};  // row 3
  EXPECT_EQ(oracle(bayer, 4, 4), want);
  expect_all_variants(bayer, 4, 4, "hand 4x4");
}

// Saturated and alternating content: the 8-bit averaging must not overflow or mis-round.
TEST(BayerDemosaic, ExtremeMosaics) {
  for (const std::uint32_t w : {2U, 16U, 34U, 66U, 130U, 640U}) {
    for (const std::uint32_t h : {2U, 4U}) {
      const std::size_t n = std::size_t{w} * h;
      Bytes ones(n, 255), checker(n), stripes(n), near(n);
      std::mt19937 rng(w + h);
      for (std::size_t i = 0; i < n; ++i) {
        checker[i] = ((i / w + i % w) % 2) ? 255 : 0;
        stripes[i] = (i % 3 == 0) ? 255 : 1;
        near[i] = static_cast<std::uint8_t>(253 + rng() % 3);
      }
      expect_all_variants(ones, w, h, "all 255");
      expect_all_variants(checker, w, h, "checker");
      expect_all_variants(stripes, w, h, "stripes");
      expect_all_variants(near, w, h, "near 255");
    }
  }
}

struct Shape {
  std::uint32_t w, h;
};

class BayerDemosaicSizes : public ::testing::TestWithParam<Shape> {};

TEST_P(BayerDemosaicSizes, EveryVariantEqualsTheOracleAndTheScalarTwin) {
  const auto [w, h] = GetParam();
  const Bytes bayer = random_mosaic(w, h, w * 1000 + h);
  expect_all_variants(bayer, w, h, "random");
  // And directly: SIMD == scalar, packed == RGB24 repacked.
  Bytes scalar(3 * bayer.size()), simd(3 * bayer.size());
  Words packed_scalar(bayer.size()), packed_simd(bayer.size());
  ok::demosaic_grbg_scalar(bayer, w, h, scalar);
  ok::demosaic_grbg(bayer, w, h, simd);
  ok::demosaic_grbg_packed_scalar(bayer, w, h, packed_scalar);
  ok::demosaic_grbg_packed(bayer, w, h, packed_simd);
  EXPECT_EQ(simd, scalar);
  EXPECT_EQ(packed_simd, packed_scalar);
  EXPECT_EQ(packed_scalar, repack(scalar));
}

std::vector<Shape> shapes() {
  std::vector<Shape> s{{2, 2}, {4, 2}, {2, 4}, {640, 480}};
  for (const std::uint32_t base : {16U, 32U, 64U, 128U}) {
    for (std::uint32_t w = base - 2; w <= base + 2; w += 2) {
      for (const std::uint32_t h : {2U, 4U, 6U}) s.push_back({w, h});
    }
  }
  for (std::uint32_t w = 2; w <= 200; w += 2) s.push_back({w, 2});  // every tail length
  return s;
}

INSTANTIATE_TEST_SUITE_P(Sizes, BayerDemosaicSizes, ::testing::ValuesIn(shapes()),
                         [](const ::testing::TestParamInfo<Shape>& param) {
                           return std::to_string(param.param.w) + "x" +
                                  std::to_string(param.param.h) + "_" + std::to_string(param.index);
                         });

// The mosaic starts right after, or ends right before, a PROT_NONE page: reading one byte outside
// the image faults in any build.
TEST(BayerDemosaicGuard, NeverReadsOutsideTheImage) {
  const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  void* map = mmap(nullptr, 3 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(map, MAP_FAILED);
  auto* base = static_cast<std::uint8_t*>(map);
  ASSERT_EQ(mprotect(base, page, PROT_NONE), 0);
  ASSERT_EQ(mprotect(base + 2 * page, page, PROT_NONE), 0);
  std::mt19937 rng(11);
  for (std::size_t i = page; i < 2 * page; ++i) base[i] = static_cast<std::uint8_t>(rng());
  for (std::uint32_t w = 2; w <= 260; w += 2) {
    for (const std::uint32_t h : {2U, 4U}) {
      const std::size_t n = std::size_t{w} * h;
      for (const std::uint8_t* image : {base + page, base + 2 * page - n}) {
        const Bytes copy(image, image + n);
        const Bytes want = oracle(copy, static_cast<int>(w), static_cast<int>(h));
        for (const Variant& v : variants()) {
          Bytes got(3 * n);
          v.rgb24({image, n}, w, h, got);
          EXPECT_EQ(got, want) << v.name << " " << w << "x" << h;
          Words got_packed(n);
          v.packed({image, n}, w, h, got_packed);
          EXPECT_EQ(got_packed, repack(want)) << v.name << " " << w << "x" << h;
        }
      }
    }
  }
  munmap(map, 3 * page);
}

// Nothing is written outside the output (sentinels on both sides; ASan watches the exact-size
// vectors of the other tests).
TEST(BayerDemosaicGuard, WritesExactlyTheOutput) {
  constexpr std::size_t PAD = 64;
  for (const std::uint32_t w : {2U, 18U, 34U, 66U, 130U, 640U}) {
    const std::uint32_t h = 4;
    const Bytes bayer = random_mosaic(w, h, w);
    const std::size_t n = bayer.size();
    for (const Variant& v : variants()) {
      Bytes got(3 * n + 2 * PAD, 0xA5);
      v.rgb24(bayer, w, h, std::span<std::uint8_t>(got).subspan(PAD, 3 * n));
      for (std::size_t i = 0; i < PAD; ++i) {
        ASSERT_EQ(got[i], 0xA5) << v.name << " wrote before the output";
        ASSERT_EQ(got[PAD + 3 * n + i], 0xA5) << v.name << " wrote past the output";
      }
      Words got_packed(n + 2 * PAD, 0xA5A5A5A5U);
      v.packed(bayer, w, h, std::span<std::uint32_t>(got_packed).subspan(PAD, n));
      for (std::size_t i = 0; i < PAD; ++i) {
        ASSERT_EQ(got_packed[i], 0xA5A5A5A5U) << v.name << " wrote before the output";
        ASSERT_EQ(got_packed[PAD + n + i], 0xA5A5A5A5U) << v.name << " wrote past the output";
      }
    }
  }
}

TEST(BayerDemosaic, MosaicThenDemosaicKeepsTheSampledBytes) {
  constexpr std::uint32_t W = 640, H = 480;
  std::mt19937 rng(3);
  Bytes rgb(3 * W * H);
  for (auto& x : rgb) x = static_cast<std::uint8_t>(rng());
  Bytes bayer(W * H), back(3 * W * H), again(W * H);
  ok::mosaic_grbg(rgb, W, H, bayer);
  ok::demosaic_grbg(bayer, W, H, back);
  ok::mosaic_grbg(back, W, H, again);
  EXPECT_EQ(again, bayer);  // the demosaic keeps every pixel's own sample
}

#ifndef NDEBUG
TEST(BayerDemosaicDeathTest, BadShapesAreBugs) {
  const Bytes bayer(12);
  Bytes rgb(36);
  Bytes short_rgb(35), short_bayer(11);
  Words packed(12);
  EXPECT_DEATH(ok::demosaic_grbg(bayer, 3, 4, rgb), "even");
  EXPECT_DEATH(ok::demosaic_grbg_scalar(bayer, 6, 2, short_rgb), "size mismatch");
  EXPECT_DEATH(ok::demosaic_grbg_packed(bayer, 4, 3, packed), "even");
  EXPECT_DEATH(ok::mosaic_grbg(rgb, 2, 6, short_bayer), "size mismatch");
}
#endif

}  // namespace
