// capsule_mask (kernels/capsule_mask.hpp): every compiled SIMD variant equals the scalar twin bit
// for bit, on random and adversarial inputs (empty, all-NaN, infinities, sizes around the lane
// counts 4/8/16, points exactly on a capsule's surface, degenerate and refused capsules); and the
// twin against a double-precision reference.
#include "kernels/capsule_mask.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kernels/detail/capsule_mask_kernel.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr float NAN_F = std::numeric_limits<float>::quiet_NaN();
constexpr float INF_F = std::numeric_limits<float>::infinity();

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
  void add(float a, float b, float c) {
    x.push_back(a);
    y.push_back(b);
    z.push_back(c);
  }
};

// An arm-like chain, a sphere (a == b), a zero-radius capsule, and three refused ones.
std::vector<ok::Capsule> capsules() {
  return {{{0.0F, 0.0F, 0.0F}, {0.0F, 0.0F, 0.3F}, 0.06F},
          {{0.0F, 0.0F, 0.3F}, {0.35F, 0.1F, 0.45F}, 0.05F},
          {{0.35F, 0.1F, 0.45F}, {0.5F, -0.2F, 0.3F}, 0.04F},
          {{-0.3F, 0.2F, 0.1F}, {-0.3F, 0.2F, 0.1F}, 0.1F},
          {{0.2F, 0.2F, 0.2F}, {0.3F, 0.3F, 0.3F}, 0.0F},
          {{0.0F, 0.0F, 0.0F}, {1.0F, 0.0F, 0.0F}, -0.5F},
          {{NAN_F, 0.0F, 0.0F}, {1.0F, 0.0F, 0.0F}, 0.5F},
          {{0.0F, 0.0F, 0.0F}, {1.0F, 0.0F, 0.0F}, INF_F}};
}

enum class Kind { RANDOM, ALL_NAN, INFINITE, SURFACE };

Cloud make_cloud(std::size_t n, Kind kind, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-0.6F, 0.7F);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  Cloud c;
  const auto caps = capsules();
  for (std::size_t i = 0; i < n; ++i) {
    float p[3] = {coord(rng), coord(rng), coord(rng)};
    if (kind == Kind::SURFACE) {
      // On the surface of a capsule: a point of its segment plus radius along a perpendicular.
      const ok::Capsule& k = caps[i % 3];
      const float t = unit(rng);
      p[0] = k.a[0] + t * (k.b[0] - k.a[0]);
      p[1] = k.a[1] + t * (k.b[1] - k.a[1]) + k.radius;
      p[2] = k.a[2] + t * (k.b[2] - k.a[2]);
    }
    if (kind == Kind::ALL_NAN || (kind == Kind::RANDOM && unit(rng) < 0.1F)) {
      p[rng() % 3] = NAN_F;
    }
    if (kind == Kind::INFINITE) { p[rng() % 3] = (i % 2 != 0U) ? INF_F : -INF_F; }
    c.add(p[0], p[1], p[2]);
  }
  return c;
}

struct Case {
  std::size_t n;
  Kind kind;
};

std::string case_name(const ::testing::TestParamInfo<Case>& p) {
  const char* kinds[] = {"random", "allnan", "infinite", "surface"};
  return std::string(kinds[static_cast<int>(p.param.kind)]) + "_" + std::to_string(p.param.n);
}

class CapsuleMask : public ::testing::TestWithParam<Case> {};

TEST_P(CapsuleMask, EverySimdVariantEqualsTheScalarTwinBitForBit) {
  const Cloud c = make_cloud(GetParam().n, GetParam().kind, 21);
  const auto caps = capsules();
  std::vector<std::uint8_t> ref(c.x.size(), 7), got(c.x.size(), 7);
  const std::size_t removed = ok::capsule_mask_scalar(c.view(), caps, ref);
  EXPECT_EQ(ok::capsule_mask(c.view(), caps, got), removed);
  EXPECT_EQ(got, ref);
  ok::detail::PreparedCapsule prepared[ok::MAX_CAPSULES];
  const std::size_t count = ok::detail::prepare_capsules(caps, prepared);
  EXPECT_EQ(count, 5U) << "the negative, NaN and infinite radius capsules are refused";
  ok::for_each_available_arch([&](auto arch) {
    std::vector<std::uint8_t> m(c.x.size(), 7);
    EXPECT_EQ(ok::detail::CapsuleMaskKernel{}(arch, c.view(), prepared, count, m), removed)
        << decltype(arch)::name();
    EXPECT_EQ(m, ref) << decltype(arch)::name();
  });
  if (GetParam().kind == Kind::ALL_NAN || GetParam().kind == Kind::INFINITE) {
    EXPECT_EQ(removed, 0U) << "a non-finite point is never inside";
  }
}

INSTANTIATE_TEST_SUITE_P(Inputs, CapsuleMask,
                         ::testing::Values(Case{0, Kind::RANDOM}, Case{1, Kind::RANDOM},
                                           Case{3, Kind::RANDOM}, Case{4, Kind::RANDOM},
                                           Case{5, Kind::RANDOM}, Case{7, Kind::RANDOM},
                                           Case{8, Kind::RANDOM}, Case{9, Kind::RANDOM},
                                           Case{15, Kind::RANDOM}, Case{16, Kind::RANDOM},
                                           Case{17, Kind::RANDOM}, Case{33, Kind::RANDOM},
                                           Case{30011, Kind::RANDOM}, Case{37, Kind::ALL_NAN},
                                           Case{19, Kind::INFINITE}, Case{4099, Kind::SURFACE}),
                         case_name);

// The twin against the distance computed in double: only points within float rounding of a
// surface may be classified either way.
TEST(CapsuleMaskReference, AgreesWithDoublePrecisionDistances) {
  const Cloud c = make_cloud(20000, Kind::RANDOM, 5);
  const auto caps = capsules();
  std::vector<std::uint8_t> mask(c.x.size());
  const std::size_t removed = ok::capsule_mask_scalar(c.view(), caps, mask);
  std::size_t expected = 0;
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    if (!std::isfinite(c.x[i]) || !std::isfinite(c.y[i]) || !std::isfinite(c.z[i])) {
      EXPECT_EQ(mask[i], 1);
      continue;
    }
    double nearest = 1e300;  // distance to the surface, negative inside
    for (std::size_t k = 0; k < 5; ++k) {
      const auto& cap = caps[k];
      const double d[3] = {double(cap.b[0]) - cap.a[0], double(cap.b[1]) - cap.a[1],
                           double(cap.b[2]) - cap.a[2]};
      const double p[3] = {double(c.x[i]) - cap.a[0], double(c.y[i]) - cap.a[1],
                           double(c.z[i]) - cap.a[2]};
      const double len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const double t =
          len2 > 0 ? std::clamp((p[0] * d[0] + p[1] * d[1] + p[2] * d[2]) / len2, 0.0, 1.0) : 0.0;
      const double e = std::hypot(p[0] - t * d[0], p[1] - t * d[1], p[2] - t * d[2]);
      nearest = std::min(nearest, e - cap.radius);
    }
    if (std::fabs(nearest) < 1e-5) {
      continue;  // within float rounding of a surface: either answer is right
    }
    EXPECT_EQ(mask[i], nearest < 0 ? 0 : 1)
        << "point " << i << " at " << nearest << " m from a surface";
    expected += nearest < 0 ? 1U : 0U;
  }
  EXPECT_NEAR(static_cast<double>(removed), static_cast<double>(expected), 3.0);
  EXPECT_GT(removed, 100U);
}

TEST(CapsuleMaskReference, CapsulesPastTheLimitAreIgnored) {
  std::vector<ok::Capsule> many(ok::MAX_CAPSULES, ok::Capsule{{5, 5, 5}, {5, 5, 5}, 0.1F});
  many.push_back({{0, 0, 0}, {0, 0, 0}, 1.0F});  // the 33rd: would cover the point
  Cloud c;
  c.add(0, 0, 0);
  std::vector<std::uint8_t> mask(1);
  EXPECT_EQ(ok::capsule_mask(c.view(), many, mask), 0U);
  EXPECT_EQ(mask[0], 1);
  EXPECT_EQ(ok::capsule_mask(c.view(), std::span(many).last(1), mask), 1U);
  EXPECT_EQ(mask[0], 0);
}

}  // namespace
