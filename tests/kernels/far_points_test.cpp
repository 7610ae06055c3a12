// Far points (kernels/far_points.hpp) and GOOD without them: no real view loses a point, one stray
// sample at 100 m, 1e30 or the float limit is left out and the view is described exactly as
// without it, by the SIMD and the scalar path alike; empty, all-NaN and small inputs.
#include "kernels/far_points.hpp"

#include <limits>

#include "tests/kernels/good_test_util.hpp"

namespace {

using namespace good_test;

const char* const REAL_VIEWS[] = {"bottle.pcd", "mug_handle.pcd", "bowl_hemisphere.pcd",
                                  "all_identical_50.pcd"};

Cloud with_point(Cloud c, std::size_t at, float x, float y, float z) {
  c.x.insert(c.x.begin() + static_cast<std::ptrdiff_t>(at), x);
  c.y.insert(c.y.begin() + static_cast<std::ptrdiff_t>(at), y);
  c.z.insert(c.z.begin() + static_cast<std::ptrdiff_t>(at), z);
  return c;
}

struct Described {
  ok::GoodResult result;
  std::vector<float> descriptor;
};

template <class Fn>
Described describe(const Cloud& c, Fn&& fn) {
  ok::GoodScratch scratch(15);
  Described d{{}, std::vector<float>(3 * 15 * 15, -1.0F)};
  auto r = fn(c.view(), ok::GoodConfig{}, scratch, std::span<float>(d.descriptor));
  EXPECT_TRUE(r.has_value());
  if (r) d.result = *r;
  return d;
}

TEST(FarPoints, NoRealViewHasAny) {
  for (const char* name : REAL_VIEWS) {
    const Cloud c = load(good_dir() / name);
    ASSERT_FALSE(c.x.empty()) << name;
    const ok::FarPoints far = ok::find_far_points(c.view());
    EXPECT_EQ(far.count, 0U) << name;
    EXPECT_GE(far.keep_radius, ok::FAR_POINT_FLOOR_M) << name;
    const Described d = describe(c, ok::compute_good);
    EXPECT_EQ(d.result.far_points, 0U) << name;
    EXPECT_EQ(d.result.flags & ok::FAR_POINTS_DROPPED, 0U) << name;
  }
}

TEST(FarPoints, OneStrayPointIsLeftOutAndTheViewDescribedAsWithoutIt) {
  const Cloud bottle = load(good_dir() / "bottle.pcd");
  const Described clean = describe(bottle, ok::compute_good);
  const float big = std::numeric_limits<float>::max();
  const struct {
    float x, y, z;
  } strays[] = {{100.0F, 0.0F, 0.0F}, {1e30F, 0.0F, 0.0F}, {big, -big, big}, {0.0F, 0.0F, -5.0F}};
  for (const auto& s : strays) {
    for (const std::size_t at : {std::size_t{0}, bottle.x.size() / 2, bottle.x.size()}) {
      const Cloud c = with_point(bottle, at, s.x, s.y, s.z);
      const ok::FarPoints far = ok::find_far_points(c.view());
      EXPECT_EQ(far.count, 1U) << s.x;
      EXPECT_TRUE(ok::is_far_point(c.view(), at, far));
      for (auto fn : {ok::compute_good, ok::compute_good_scalar}) {
        const Described d = describe(c, fn);
        EXPECT_EQ(d.result.far_points, 1U);
        EXPECT_NE(d.result.flags & ok::FAR_POINTS_DROPPED, 0U);
        EXPECT_EQ(d.result.points_used, bottle.x.size());
        for (const float v : d.result.bbox) EXPECT_TRUE(std::isfinite(v));
        for (const float v : d.result.frame) EXPECT_TRUE(std::isfinite(v));
        EXPECT_EQ(d.result.frame, clean.result.frame);
        EXPECT_EQ(d.result.bbox, clean.result.bbox);
        EXPECT_LE(l1(d.descriptor, clean.descriptor), 1e-3) << "at " << at << " x " << s.x;
      }
      const Described simd = describe(c, ok::compute_good);
      const Described scalar = describe(c, ok::compute_good_scalar);
      EXPECT_EQ(simd.result.frame, scalar.result.frame);
      EXPECT_LE(l1(simd.descriptor, scalar.descriptor), 1e-3);
    }
  }
}

TEST(FarPoints, NonFinitePointsAreNeitherSampledNorFar) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  Cloud c = load(good_dir() / "mug_handle.pcd");
  for (std::size_t i = 0; i < c.x.size(); i += 3) c.x[i] = nan;  // one in three, every sample row
  c = with_point(c, 7, inf, 0.0F, 0.0F);
  const ok::FarPoints far = ok::find_far_points(c.view());
  EXPECT_EQ(far.count, 0U);
  EXPECT_FALSE(ok::is_far_point(c.view(), 7, far));
  const Described d = describe(c, ok::compute_good);
  EXPECT_NE(d.result.flags & ok::NAN_IGNORED, 0U);
  EXPECT_EQ(d.result.flags & ok::FAR_POINTS_DROPPED, 0U);
}

TEST(FarPoints, EmptyAllNanAndSmallInputs) {
  EXPECT_EQ(ok::find_far_points(Cloud{}.view()).count, 0U);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(ok::find_far_points(Cloud{{nan, nan}, {0, 0}, {0, 0}}.view()).count, 0U);
  // Fewer finite points than FAR_POINT_MIN_SAMPLES: too few to judge, nothing is far.
  const Cloud three{{0.0F, 0.01F, 50.0F}, {0.0F, 0.0F, 0.0F}, {1.0F, 1.0F, 1.0F}};
  EXPECT_EQ(ok::find_far_points(three.view()).count, 0U);
  // Sizes around the sample count: a compact cube of n points and one stray at 1 km.
  for (const std::size_t n : {ok::FAR_POINT_MIN_SAMPLES, std::size_t{254}, std::size_t{255},
                              std::size_t{256}, std::size_t{511}, std::size_t{1000}}) {
    Cloud cube;
    for (std::size_t i = 0; i < n; ++i) {
      cube.x.push_back(0.01F * static_cast<float>(i % 10));
      cube.y.push_back(0.01F * static_cast<float>((i / 10) % 10));
      cube.z.push_back(1.0F + 0.01F * static_cast<float>(i / 100));
    }
    EXPECT_EQ(ok::find_far_points(cube.view()).count, 0U) << n;
    const Cloud stray = with_point(cube, n / 3, 1000.0F, 0.0F, 0.0F);
    EXPECT_EQ(ok::find_far_points(stray.view()).count, 1U) << n;
    std::vector<float> x(n), y(n), z(n);
    const ok::FarPoints far = ok::find_far_points(stray.view());
    EXPECT_EQ(ok::copy_near_points(stray.view(), far, ok::PointsSpan{x, y, z}), n);
    EXPECT_EQ(x, cube.x);
  }
}

TEST(FarPoints, ABulkInTwoPartsKeepsBoth) {
  // 60 % of the points in a 2 cm blob, 40 % in another blob 0.5 m away (a band's two ends).
  Cloud c;
  for (int i = 0; i < 500; ++i) {
    const float base = i % 5 < 3 ? 0.0F : 0.5F;
    c.x.push_back(base + 0.0001F * static_cast<float>(i % 200));
    c.y.push_back(0.0001F * static_cast<float>(i % 97));
    c.z.push_back(1.0F);
  }
  EXPECT_EQ(ok::find_far_points(c.view()).count, 0U);
}

TEST(FarPoints, NothingWithinTheFloorIsEverFar) {
  // A tight 1 cm cluster and a point 9 cm away: hundreds of radii out, but inside the 10 cm floor.
  Cloud c;
  for (int i = 0; i < 100; ++i) {
    c.x.push_back(0.0001F * static_cast<float>(i));
    c.y.push_back(0.0F);
    c.z.push_back(1.0F);
  }
  c = with_point(c, 50, 0.09F, 0.0F, 1.0F);
  EXPECT_EQ(ok::find_far_points(c.view()).count, 0U);
}

}  // namespace
