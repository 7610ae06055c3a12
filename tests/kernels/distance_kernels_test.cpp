// distances() and nearest_k() against their scalar twins on every architecture, with the tolerances
// stated in kernels/distance.hpp, plus hand-computed values for each metric.
#include "kernels/distance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "kernels/detail/distance_kernel.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr ok::Metric ALL[] = {ok::Metric::L1,           ok::Metric::L2,
                              ok::Metric::L2_SQUARED,   ok::Metric::CHI_SQUARED,
                              ok::Metric::SYMMETRIC_KL, ok::Metric::JENSEN_SHANNON};

struct Store {
  std::vector<float> data;
  std::size_t dims, count, stride;
  ok::DescriptorMatrixView view() const { return {data, dims, count, stride}; }
};

// Random histograms (unit sum per descriptor), with exact zeros and some duplicate columns.
Store random_store(std::size_t dims, std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  Store s{std::vector<float>(dims * (count + 3), 0.0F), dims, count, count + 3};
  for (std::size_t j = 0; j < count; ++j) {
    float sum = 0.0F;
    for (std::size_t d = 0; d < dims; ++d) {
      const float v = u(rng) < 0.4F ? 0.0F : u(rng);
      s.data[d * s.stride + j] = v;
      sum += v;
    }
    for (std::size_t d = 0; d < dims && sum > 0.0F; ++d) { s.data[d * s.stride + j] /= sum; }
    if (j % 5 == 4) {
      for (std::size_t d = 0; d < dims; ++d) {
        s.data[d * s.stride + j] = s.data[d * s.stride + j - 1];
      }
    }
  }
  return s;
}

std::vector<float> column(const Store& s, std::size_t j) {
  std::vector<float> q(s.dims);
  for (std::size_t d = 0; d < s.dims; ++d) { q[d] = s.data[d * s.stride + j]; }
  return q;
}

double tolerance(ok::Metric m, float ref) {
  switch (m) {
    case ok::Metric::L1:
      return 0.0;
    case ok::Metric::SYMMETRIC_KL:
    case ok::Metric::JENSEN_SHANNON:
      return 1e-4 * std::abs(ref) + 1e-6;
    default:
      return 1e-5 * std::abs(ref);
  }
}

class DistanceSizes : public ::testing::TestWithParam<std::size_t> {};

TEST_P(DistanceSizes, EveryArchWithinToleranceOfScalar) {
  const std::size_t count = GetParam();
  const Store s = random_store(75, count, static_cast<std::uint32_t>(count) + 3U);
  const Store qs = random_store(75, 1, 99U);
  const std::vector<float> q = column(qs, 0);
  for (const ok::Metric m : ALL) {
    std::vector<float> ref(count), got(count);
    EXPECT_EQ(ok::distances_scalar(q, s.view(), m, ref), count);
    EXPECT_EQ(ok::distances(q, s.view(), m, got), count);
    for (std::size_t j = 0; j < count; ++j) {
      EXPECT_NEAR(got[j], ref[j], tolerance(m, ref[j])) << ok::to_string(m);
    }
    ok::for_each_available_arch([&](auto arch) {
      std::vector<float> a(count, -1.0F);
      ok::detail::DistanceKernel{}(arch, q, s.view(), m, a);
      for (std::size_t j = 0; j < count; ++j) {
        ASSERT_NEAR(a[j], ref[j], tolerance(m, ref[j]))
            << ok::to_string(m) << " " << decltype(arch)::name() << " j " << j;
      }
    });
  }
}

// 0, 1, around 4/8/16 lanes and the 4-register blocks (16/32/64 columns), and larger.
INSTANTIATE_TEST_SUITE_P(Sizes, DistanceSizes,
                         ::testing::Values(0, 1, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 32, 33, 63, 64,
                                           65, 1000));

TEST(Distance, HandComputedValues) {
  // Two descriptors as columns: q = (0.5, 0.5, 0), b0 = q, b1 = (0, 0.5, 0.5).
  const Store s{{0.5F, 0.0F, 0.5F, 0.5F, 0.0F, 0.5F}, 3, 2, 2};
  const std::vector<float> q{0.5F, 0.5F, 0.0F};
  std::vector<float> d(2);
  const auto get = [&](ok::Metric m) {
    EXPECT_EQ(ok::distances(q, s.view(), m, d), 2U);
    EXPECT_NEAR(d[0], 0.0F, 1e-5) << ok::to_string(m);
    return d[1];
  };
  EXPECT_FLOAT_EQ(get(ok::Metric::L1), 1.0F);
  EXPECT_FLOAT_EQ(get(ok::Metric::L2_SQUARED), 0.5F);
  EXPECT_FLOAT_EQ(get(ok::Metric::L2), std::sqrt(0.5F));
  EXPECT_FLOAT_EQ(get(ok::Metric::CHI_SQUARED), 1.0F);  // 0.25/0.5 + 0 + 0.25/0.5
  EXPECT_NEAR(get(ok::Metric::JENSEN_SHANNON), std::log(2.0) / 2.0,
              1e-6);  // half the mass disjoint
  const double e = ok::DISTANCE_KL_EPSILON;
  EXPECT_NEAR(get(ok::Metric::SYMMETRIC_KL), 2 * 0.5 * (std::log(0.5 + e) - std::log(e)), 1e-3);
}

TEST(Distance, NearestKMatchesScalarAndIsSortedWithStableTies) {
  const Store s = random_store(675, 1000, 5U);
  const std::vector<float> q = column(s, 17);  // a stored descriptor: distance 0 to itself
  for (const ok::Metric m : ALL) {
    std::vector<float> scratch(s.count);
    std::vector<ok::Neighbor> a(10), b(10);
    ASSERT_EQ(ok::nearest_k(q, s.view(), m, scratch, a), 10U);
    ASSERT_EQ(ok::nearest_k_scalar(q, s.view(), m, scratch, b), 10U);
    EXPECT_EQ(a[0].index, 17U) << ok::to_string(m);
    for (std::size_t i = 1; i < a.size(); ++i) { EXPECT_LE(a[i - 1].distance, a[i].distance); }
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].index, b[i].index) << ok::to_string(m) << " rank " << i;
    }
  }
  // Column 19 duplicates 18 (every fifth column repeats its left neighbour): equal distances, lower
  // index first.
  const std::vector<float> q18 = column(s, 18);
  std::vector<float> scratch(s.count);
  std::vector<ok::Neighbor> two(2);
  ASSERT_EQ(ok::nearest_k(q18, s.view(), ok::Metric::L1, scratch, two), 2U);
  EXPECT_EQ(two[0].index, 18U);
  EXPECT_EQ(two[1].index, 19U);
}

TEST(Distance, NearestKWithFewerStoredThanKAndNaN) {
  Store s{{0.0F, std::numeric_limits<float>::quiet_NaN(), 2.0F}, 1, 3, 3};
  const std::vector<float> q{1.9F};
  std::vector<float> scratch(3);
  std::vector<ok::Neighbor> out(5);
  ASSERT_EQ(ok::nearest_k(q, s.view(), ok::Metric::L1, scratch, out), 3U);
  EXPECT_EQ(out[0].index, 2U);
  EXPECT_EQ(out[1].index, 0U);
  EXPECT_EQ(out[2].index, 1U);  // NaN last
  std::vector<ok::Neighbor> none;
  EXPECT_EQ(ok::nearest_k(q, s.view(), ok::Metric::L1, scratch, none), 0U);
}

TEST(DistanceDeathTest, WrongShapesAreBugs) {
  const Store s = random_store(4, 3, 1U);
  std::vector<float> out(3);
  const std::vector<float> bad_query(5, 0.0F);
  EXPECT_DEATH(static_cast<void>(ok::distances(bad_query, s.view(), ok::Metric::L1, out)),
               "query length");
}

}  // namespace
