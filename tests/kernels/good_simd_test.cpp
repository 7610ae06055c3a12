// GOOD's SIMD passes against their scalar twins, on every architecture the CPU has: random clouds
// with NaN/Inf, sizes around 4/8/16 lanes, duplicates and huge coordinates; then whole descriptors.
#include <limits>

#include "kernels/detail/good_kernel.hpp"
#include "kernels/detail/pca_moments_kernel.hpp"
#include "tests/kernels/good_test_util.hpp"

namespace {

using namespace good_test;
namespace od = orthoflow::kernels::detail;

Cloud random_cloud(std::size_t n, std::uint32_t seed, float scale, float bad_share) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-scale, scale);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity()};
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    float p[3] = {coord(rng), 0.5F * coord(rng), 0.25F * coord(rng)};
    if (unit(rng) < bad_share) { p[rng() % 3] = specials[rng() % 3]; }
    if (i % 7 == 3 && i > 0) {
      p[0] = c.x.back(), p[1] = c.y.back(), p[2] = c.z.back();
    }  // duplicates
    c.x.push_back(p[0]);
    c.y.push_back(p[1]);
    c.z.push_back(p[2]);
  }
  return c;
}

od::GoodTransform some_transform() {
  od::GoodTransform t;
  t.c = {0.01F, -0.02F, 0.03F};
  t.r = {{{0.36F, 0.48F, -0.8F}, {-0.8F, 0.6F, 0.0F}, {0.48F, 0.64F, 0.6F}}};
  return t;
}

struct SimdCase {
  std::size_t n;
  float scale;
};

class GoodSimd : public ::testing::TestWithParam<SimdCase> {};

TEST_P(GoodSimd, StatsAndBinsEqualScalarOnEveryArch) {
  const Cloud c = random_cloud(GetParam().n, static_cast<std::uint32_t>(GetParam().n) + 11U,
                               GetParam().scale, 0.1F);
  const od::GoodTransform t = some_transform();
  const float inf = std::numeric_limits<float>::infinity();
  od::GoodStats ref{{inf, inf, inf}, {-inf, -inf, -inf}, {0, 0}, {0, 0}};
  od::good_stats_scalar(c.view(), t, 0.05F * GetParam().scale, 0, c.x.size(), ref);
  od::GoodBinParams p{t, 0.6F * GetParam().scale, 0.12F * GetParam().scale, 10};
  std::vector<std::uint32_t> ref_counts(303, 0U);
  od::good_bin_range_scalar(c.view(), p, 0, c.x.size(), ref_counts);
  ok::for_each_available_arch([&](auto arch) {
    const od::GoodStats s = od::GoodStatsKernel{}(arch, c.view(), t, 0.05F * GetParam().scale);
    const std::string name = decltype(arch)::name();
    // Tolerance of good.hpp: FMA contraction may change a coordinate by one rounding, so an extreme
    // moves by ~1e-7 relative and a point sitting on the threshold or a bin edge may change side.
    const double tol = 1e-5 * GetParam().scale;
    for (std::size_t a = 0; a < 3; ++a) {
      if (s.min[a] != ref.min[a]) {
        EXPECT_NEAR(s.min[a], ref.min[a], tol) << name;
      }  // equal covers +-inf
      if (s.max[a] != ref.max[a]) { EXPECT_NEAR(s.max[a], ref.max[a], tol) << name; }
    }
    for (std::size_t a = 0; a < 2; ++a) {
      EXPECT_LE(std::abs(static_cast<long>(s.pos[a]) - static_cast<long>(ref.pos[a])), 1) << name;
      EXPECT_LE(std::abs(static_cast<long>(s.neg[a]) - static_cast<long>(ref.neg[a])), 1) << name;
    }
    std::vector<std::uint32_t> counts(303, 0U);
    od::GoodBinKernel{}(arch, c.view(), p, counts);
    long moved = 0;  // over the cells and the three drop slots
    for (std::size_t i = 0; i < counts.size(); ++i) {
      moved += std::abs(static_cast<long>(counts[i]) - static_cast<long>(ref_counts[i]));
    }
    EXPECT_LE(moved, 6) << name;
    if (!name.starts_with("avx") && !name.starts_with("fma")) {  // no FMA in the SSE2 unit: exact
      EXPECT_EQ(counts, ref_counts) << name;
      EXPECT_EQ(s.min, ref.min) << name;
    }
  });
}

INSTANTIATE_TEST_SUITE_P(Sizes, GoodSimd,
                         ::testing::Values(SimdCase{0, 1.0F}, SimdCase{1, 1.0F}, SimdCase{3, 1.0F},
                                           SimdCase{4, 1.0F}, SimdCase{5, 1.0F}, SimdCase{7, 1.0F},
                                           SimdCase{8, 1.0F}, SimdCase{9, 1.0F}, SimdCase{15, 1.0F},
                                           SimdCase{16, 1.0F}, SimdCase{17, 1.0F},
                                           SimdCase{33, 1.0F}, SimdCase{1000, 0.1F},
                                           SimdCase{5003, 1e30F}));

TEST(PcaMoments, EveryArchWithinToleranceOfScalar) {
  for (const std::size_t n : {1U, 3U, 4U, 5U, 8U, 9U, 17U, 1000U}) {
    const Cloud c = random_cloud(n, static_cast<std::uint32_t>(n), 1.0F, 0.2F);
    const ok::PcaMoments ref = ok::pca_moments_scalar(c.view());
    const std::size_t first = od::first_finite(c.view());
    if (first == n) { continue; }
    ok::for_each_available_arch([&](auto arch) {
      ok::PcaMoments m;
      m.origin = ref.origin;
      m = od::PcaMomentsKernel{}(arch, c.view(), m);
      EXPECT_EQ(m.count, ref.count);
      for (std::size_t a = 0; a < 3; ++a) {
        EXPECT_NEAR(m.sum[a], ref.sum[a], 1e-12 * (1.0 + std::abs(ref.sum[a])));
      }
      for (std::size_t a = 0; a < 6; ++a) {
        EXPECT_NEAR(m.sq[a], ref.sq[a], 1e-12 * (1.0 + std::abs(ref.sq[a])));
      }
    });
  }
}

TEST(GoodSimd, AllNaNCountsNothing) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Cloud c{std::vector<float>(37, nan), std::vector<float>(37, 0.0F),
                std::vector<float>(37, 1.0F)};
  ok::for_each_available_arch([&](auto arch) {
    const od::GoodStats s = od::GoodStatsKernel{}(arch, c.view(), some_transform(), 0.0F);
    EXPECT_EQ(s.pos[0] + s.neg[0] + s.pos[1] + s.neg[1], 0U);
    std::vector<std::uint32_t> counts(78, 0U);
    od::GoodBinKernel{}(arch, c.view(), od::GoodBinParams{some_transform(), 1.0F, 0.4F, 5}, counts);
    EXPECT_EQ(counts[75] + counts[76] + counts[77], 3U * 37U);  // every point dropped by every view
  });
}

TEST(GoodSimd, DispatchedDescriptorEqualsScalarTwin) {
  for (const char* name :
       {"mug_handle", "box", "cone", "sphere", "duplicates", "mug_handle_far", "two_points"}) {
    const Cloud c = load(good_dir() / (std::string(name) + ".pcd"));
    for (const auto mode : {ok::GoodMode::INVARIANT, ok::GoodMode::REFERENCE}) {
      for (const std::size_t bins : {5U, 15U}) {
        const ok::GoodConfig cfg{bins, mode, std::nullopt};
        ok::GoodScratch scratch(bins);
        std::vector<float> a(3 * bins * bins), b(3 * bins * bins);
        const auto ra = ok::compute_good(c.view(), cfg, scratch, a);
        const auto rb = ok::compute_good_scalar(c.view(), cfg, scratch, b);
        ASSERT_TRUE(ra.has_value() && rb.has_value());
        EXPECT_LE(l1(a, b), 1e-3) << name;  // a point may move across a bin edge (good.hpp @note)
        for (std::size_t k = 0; k < 16; ++k) {
          EXPECT_NEAR(ra->frame[k], rb->frame[k], 1e-5) << name;
        }
        EXPECT_EQ(ra->order, rb->order) << name;
        EXPECT_EQ(ra->kept, rb->kept) << name;
      }
    }
  }
}

}  // namespace
