// RANSAC plane (seeded, portable), fit_plane, convex hull and prism on constructed scenes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/rng.hpp"
#include "kernels/polygonal_prism.hpp"
#include "kernels/ransac_plane.hpp"

namespace ok = orthoflow::kernels;

namespace {

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
  void add(float a, float b, float c) { x.push_back(a), y.push_back(b), z.push_back(c); }
};

TEST(SegRng, GoldenSequenceIsPortable) {
  // xoshiro256** seeded by splitmix64(0): first outputs computed independently (Python big
  // integers).
  orthoflow::core::Rng rng(0);
  EXPECT_EQ(rng.next(), 0x99EC5F36CB75F2B4ULL);
  EXPECT_EQ(rng.next(), 0xBF6E1F784956452AULL);
  orthoflow::core::Rng a(42), b(42);
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t v = a.below(7);
    EXPECT_LT(v, 7U);
    EXPECT_EQ(v, b.below(7));
  }
}

/// A tilted table (normal ~ (0, -0.83, -0.56) like mOSD), noise +-3 mm, plus outliers above it.
Cloud table_scene(std::size_t table, std::size_t clutter, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uv(-0.5F, 0.5F), noise(-0.003F, 0.003F), up(0.02F, 0.3F);
  const float n[3] = {0.0F, -0.83F, -0.5577F};  // unit (to 1e-4)
  const float u[3] = {1.0F, 0.0F, 0.0F}, v[3] = {0.0F, 0.5577F, -0.83F};
  const float o[3] = {0.0F, 0.3F, 1.2F};
  Cloud c;
  for (std::size_t i = 0; i < table + clutter; ++i) {
    const float a = uv(rng), b = uv(rng), h = i < table ? noise(rng) : up(rng);
    c.add(o[0] + a * u[0] + b * v[0] + h * n[0], o[1] + a * u[1] + b * v[1] + h * n[1],
          o[2] + a * u[2] + b * v[2] + h * n[2]);
  }
  return c;
}

TEST(SegRansac, FindsTableScalarAndSimdAgree) {
  const Cloud c = table_scene(3000, 1500, 1);
  std::vector<std::uint32_t> in_a(c.x.size()), in_b(c.x.size());
  auto a = ok::ransac_plane(c.view(), {}, in_a);
  auto b = ok::ransac_plane_scalar(c.view(), {}, in_b);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->iterations, 200U);
  EXPECT_NEAR(a->plane.normal[1], -0.83F, 0.01F);
  EXPECT_NEAR(a->plane.normal[2], -0.5577F, 0.01F);
  EXPECT_GT(a->plane.d, 0.0F);  // sensor side positive
  EXPECT_GE(a->inliers, 2990U);
  EXPECT_LE(a->inliers, 3100U);
  EXPECT_NEAR(a->plane.d, b->plane.d, 1e-4F);
  EXPECT_NEAR(double(a->inliers), double(b->inliers), 5.0);
  for (std::size_t k = 1; k < a->inliers; ++k) { EXPECT_LT(in_a[k - 1], in_a[k]); }
}

TEST(SegRansac, EarlyStopAndDeterminism) {
  const Cloud c = table_scene(2000, 200, 2);
  std::vector<std::uint32_t> idx(c.x.size());
  ok::RansacParams p;
  p.confidence = 0.99;
  auto a = ok::ransac_plane(c.view(), p, idx);
  auto b = ok::ransac_plane(c.view(), p, idx);
  ASSERT_TRUE(a && b);
  EXPECT_LT(a->iterations, 20U);  // 90 % inliers: a handful of draws suffice at 0.99
  EXPECT_EQ(a->iterations, b->iterations);
  EXPECT_EQ(a->plane.d, b->plane.d);
  p.seed = 7;
  auto other = ok::ransac_plane(c.view(), p, idx);
  ASSERT_TRUE(other);
  EXPECT_NEAR(other->plane.d, a->plane.d, 1e-3F);
}

TEST(SegRansac, EveryErrorCode) {
  using Code = ok::RansacError::Code;
  Cloud c = table_scene(100, 0, 3);
  std::vector<std::uint32_t> idx(c.x.size());
  ok::RansacParams bad;
  bad.tau = -1.0F;
  EXPECT_EQ(ok::ransac_plane(c.view(), bad, idx).error().code, Code::BAD_PARAMS);
  bad = {};
  bad.max_iterations = 0;
  EXPECT_EQ(ok::ransac_plane(c.view(), bad, idx).error().code, Code::BAD_PARAMS);
  bad = {};
  bad.confidence = 1.0;
  EXPECT_EQ(ok::ransac_plane(c.view(), bad, idx).error().code, Code::BAD_PARAMS);
  Cloud two;
  two.add(0, 0, 1), two.add(1, 0, 1), two.add(std::numeric_limits<float>::quiet_NaN(), 0, 0);
  EXPECT_EQ(ok::ransac_plane(two.view(), {}, idx).error().code, Code::TOO_FEW_POINTS);
  Cloud line;
  for (int i = 0; i < 50; ++i) { line.add(float(i), 2.0F * float(i), 1.0F); }
  line.add(0, 0, 1);  // duplicates and collinear only
  auto degenerate = ok::ransac_plane(line.view(), {}, idx);
  ASSERT_FALSE(degenerate);
  EXPECT_EQ(degenerate.error().code, Code::NO_HYPOTHESIS);
  EXPECT_FALSE(degenerate.error().to_string().empty());
  std::vector<std::uint32_t> small(10);
  EXPECT_EQ(ok::ransac_plane(c.view(), {}, small).error().code, Code::OUTPUT_TOO_SMALL);
}

std::vector<std::uint32_t> hull_of(const std::vector<double>& u, const std::vector<double>& v) {
  std::vector<std::uint32_t> scratch(u.size()), hull(u.size() + 1);
  hull.resize(ok::convex_hull_2d(u, v, scratch, hull));
  return hull;
}

TEST(SegHull, SquareWithInteriorCollinearAndDuplicatePoints) {
  std::vector<double> u{0, 1, 1, 0, 0.5, 0.5, 1, 0, 0.3, 1}, v{0, 0, 1, 1, 0, 0.5, 0.5, 0, 0.7, 1};
  const auto h = hull_of(u, v);  // corners 0 1 2 3; edge midpoints 4, 6 and duplicates 7, 9 dropped
  EXPECT_EQ(h, (std::vector<std::uint32_t>{0, 1, 2, 3}));
}

TEST(SegHull, DegenerateInputs) {
  EXPECT_TRUE(hull_of({}, {}).empty());
  EXPECT_EQ(hull_of({1.0}, {2.0}).size(), 1U);
  EXPECT_EQ(hull_of({1, 1, 1}, {2, 2, 2}).size(), 1U);
  EXPECT_EQ(hull_of({0, 1, 2, 3}, {0, 1, 2, 3}).size(), 2U);  // collinear
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(hull_of({0, nan, 1, 0}, {0, 0, 0, 1}).size(), 3U);
}

TEST(SegHull, RandomDiscContainsAllPoints) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  std::vector<double> u, v;
  for (int i = 0; i < 5000; ++i) { u.push_back(d(rng)), v.push_back(d(rng)); }
  const auto h = hull_of(u, v);
  std::vector<double> hu, hv;
  for (auto i : h) { hu.push_back(u[i]), hv.push_back(v[i]); }
  ASSERT_GE(h.size(), 8U);
  for (std::size_t i = 0; i < u.size(); ++i) {
    EXPECT_TRUE(ok::inside_convex_polygon(hu, hv, u[i], v[i])) << i;
  }
  EXPECT_FALSE(ok::inside_convex_polygon(hu, hv, 1.5, 0.0));
}

TEST(SegPrism, KeepsObjectsAboveTheTableOnly) {
  Cloud c = table_scene(2000, 0, 4);
  const std::size_t table_points = c.x.size();
  c.add(0.0F, 0.3F - 0.83F * 0.1F, 1.2F - 0.5577F * 0.1F);  // 10 cm above the middle
  c.add(0.0F, 0.3F + 0.83F * 0.1F, 1.2F + 0.5577F * 0.1F);  // 10 cm below
  c.add(2.0F, 0.3F - 0.83F * 0.1F, 1.2F - 0.5577F * 0.1F);  // above the plane but off the table
  std::vector<std::uint32_t> idx(c.x.size());
  auto plane = ok::ransac_plane(c.view(), {}, idx);
  ASSERT_TRUE(plane);
  const ok::PlaneBasis basis = ok::make_plane_basis(plane->plane);
  std::vector<double> u(plane->inliers), v(plane->inliers);
  ok::project_to_plane(c.view(), std::span(idx).first(plane->inliers), basis, u, v);
  const auto h = hull_of(u, v);
  std::vector<double> hu, hv;
  for (auto i : h) { hu.push_back(u[i]), hv.push_back(v[i]); }
  const ok::Prism prism{plane->plane, basis, hu, hv, 0.02F, 0.5F};
  std::vector<float> heights(c.x.size());
  std::vector<std::uint8_t> mask(c.x.size());
  EXPECT_EQ(ok::polygonal_prism(c.view(), prism, heights, mask), 1U);
  EXPECT_EQ(mask[table_points], 1);
  EXPECT_NEAR(heights[table_points], 0.1F, 0.005F);
}

}  // namespace
