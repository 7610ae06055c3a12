// kernels/pca_frame.hpp: the SIMD moments equal the scalar twin within the header's tolerance, the
// frame recovers known axes and eigenvalues, and every PcaError is triggered.
#include "kernels/pca_frame.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/rng.hpp"

namespace ok = orthoflow::kernels;

namespace {

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
};

/// Approximately standard normal (Irwin-Hall: 12 uniforms minus 6), portable.
double normal(orthoflow::core::Rng& rng) {
  double sum = 0.0;
  for (int i = 0; i < 12; ++i) { sum += static_cast<double>(rng.next() >> 11) * 0x1.0p-53; }
  return sum - 6.0;
}

/// An anisotropic blob: standard deviations 0.3, 0.1, 0.02 along x, y, z, centred at @p c, some
/// NaN.
Cloud blob(std::size_t n, double c, std::uint64_t seed) {
  orthoflow::core::Rng rng(seed);
  Cloud out;
  for (std::size_t i = 0; i < n; ++i) {
    const bool nan = i % 11 == 5;
    out.x.push_back(nan ? std::numeric_limits<float>::quiet_NaN()
                        : static_cast<float>(c + 0.3 * normal(rng)));
    out.y.push_back(static_cast<float>(c + 0.1 * normal(rng)));
    out.z.push_back(static_cast<float>(c + 0.02 * normal(rng)));
  }
  return out;
}

double rel(double a, double b) {
  return std::fabs(a - b) / std::max({std::fabs(a), std::fabs(b), 1e-300});
}

class PcaMomentsSizes : public ::testing::TestWithParam<std::size_t> {};

TEST_P(PcaMomentsSizes, SimdEqualsScalarWithinTolerance) {
  const Cloud c = blob(GetParam(), 100.0, GetParam() + 1);
  const ok::PcaMoments a = ok::pca_moments(c.view());
  const ok::PcaMoments b = ok::pca_moments_scalar(c.view());
  ASSERT_EQ(a.count, b.count);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(a.origin[k], b.origin[k]);
    EXPECT_LE(rel(a.sum[k], b.sum[k]), 1e-12) << k;
  }
  for (std::size_t k = 0; k < 6; ++k) { EXPECT_LE(rel(a.sq[k], b.sq[k]), 1e-12) << k; }
}

INSTANTIATE_TEST_SUITE_P(Sizes, PcaMomentsSizes,
                         ::testing::Values(0, 1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 33, 10007));

TEST(PcaFrame, RecoversKnownAxesFarFromTheOrigin) {
  const Cloud c =
      blob(20000, 1000.0, 3);  // 1 km away: moments about the first point keep precision
  auto f = ok::compute_pca_frame(c.view());
  ASSERT_TRUE(f);
  EXPECT_NEAR(std::sqrt(f->eigenvalues[0]), 0.3, 0.01);
  EXPECT_NEAR(std::sqrt(f->eigenvalues[1]), 0.1, 0.005);
  EXPECT_NEAR(std::sqrt(f->eigenvalues[2]), 0.02, 0.001);
  EXPECT_GT(std::fabs(f->axes[0][0]), 0.999);  // v1 along x, v2 along y, v3 = v1 x v2 along z
  EXPECT_GT(std::fabs(f->axes[1][1]), 0.999);
  EXPECT_GT(std::fabs(f->axes[2][2]), 0.999);
  EXPECT_NEAR(f->centroid[1], 1000.0, 0.01);
  EXPECT_NE(f->flags & ok::NAN_IGNORED, 0U);
  EXPECT_EQ(f->flags & ok::FRAME_UNRELIABLE, 0U);
  auto s = ok::compute_pca_frame_scalar(c.view());
  ASSERT_TRUE(s);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_LE(rel(f->eigenvalues[k], s->eigenvalues[k]), 1e-9);
  }
}

TEST(PcaFrame, ErrorsAreReported) {
  const Cloud empty;
  auto e = ok::compute_pca_frame(empty.view());
  ASSERT_FALSE(e);
  EXPECT_EQ(e.error(), ok::PcaError::EMPTY_CLOUD);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Cloud all_nan{{nan, nan}, {0.0F, 1.0F}, {1.0F, 2.0F}};
  auto n = ok::compute_pca_frame(all_nan.view());
  ASSERT_FALSE(n);
  EXPECT_EQ(n.error(), ok::PcaError::NO_FINITE_POINTS);
  EXPECT_STRNE(ok::to_string(ok::PcaError::EMPTY_CLOUD),
               ok::to_string(ok::PcaError::NO_FINITE_POINTS));
}

}  // namespace
