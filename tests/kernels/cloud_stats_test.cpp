#include "kernels/cloud_stats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "kernels/detail/cloud_stats_kernel.hpp"

namespace ok = orthoflow::kernels;

namespace {

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
};

Cloud random_cloud(std::size_t n, std::uint32_t seed, float nan_share) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-1e6F, 1e6F);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity()};
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    float p[3] = {coord(rng), coord(rng), coord(rng)};
    if (unit(rng) < nan_share) { p[rng() % 3] = specials[rng() % 3]; }
    c.x.push_back(p[0]);
    c.y.push_back(p[1]);
    c.z.push_back(p[2]);
  }
  return c;
}

void expect_same(const ok::CloudStats& a, const ok::CloudStats& b, const std::string& what) {
  EXPECT_EQ(a.finite, b.finite) << what;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.min[k], b.min[k]) << what << " axis " << k;
    EXPECT_EQ(a.max[k], b.max[k]) << what << " axis " << k;
  }
}

class CloudStatsSizes : public ::testing::TestWithParam<std::size_t> {};

TEST_P(CloudStatsSizes, EveryArchEqualsScalar) {
  const Cloud c = random_cloud(GetParam(), static_cast<std::uint32_t>(GetParam()) + 7U, 0.3F);
  const ok::CloudStats ref = ok::cloud_stats_scalar(c.view());
  expect_same(ok::cloud_stats(c.view()), ref, "dispatched");
  ok::for_each_available_arch([&](auto arch) {
    expect_same(ok::detail::CloudStatsKernel{}(arch, c.view()), ref, decltype(arch)::name());
  });
}

// 0, 1, around every lane count in use (4, 8, 16), and large.
INSTANTIATE_TEST_SUITE_P(Sizes, CloudStatsSizes,
                         ::testing::Values(0, 1, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 33, 1000,
                                           100003));

TEST(CloudStats, EmptyGivesEmptyBox) {
  const Cloud c;
  const ok::CloudStats s = ok::cloud_stats(c.view());
  EXPECT_EQ(s.finite, 0U);
  EXPECT_GT(s.min[0], s.max[0]);
}

TEST(CloudStats, AllNaNCountsNothing) {
  Cloud c;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  c.x.assign(37, nan);
  c.y.assign(37, 0.0F);
  c.z.assign(37, 1.0F);
  EXPECT_EQ(ok::cloud_stats(c.view()).finite, 0U);
}

TEST(CloudStats, BoundsKnownPoints) {
  Cloud c{{1.0F, -2.0F, 3.0F}, {0.5F, 0.25F, -4.0F}, {9.0F, 8.0F, 7.0F}};
  const ok::CloudStats s = ok::cloud_stats(c.view());
  EXPECT_EQ(s.finite, 3U);
  EXPECT_EQ(s.min[0], -2.0F);
  EXPECT_EQ(s.max[1], 0.5F);
  EXPECT_EQ(s.min[2], 7.0F);
}

TEST(SimdArch, DispatchedArchIsNamed) {
  const std::string name = ok::simd_arch_name();
#if defined(__aarch64__)
  EXPECT_EQ(name, "arm64+neon");
#else
  EXPECT_TRUE(name == "avx512bw" || name == "fma3+avx2" || name == "sse2") << name;
#endif
}

}  // namespace
