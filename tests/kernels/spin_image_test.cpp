// spin_images and voxel_keypoints (kernels/spin_image.hpp): an image computed by hand; every
// compiled SIMD variant and the dispatched kernel equal the scalar twin bit for bit on random and
// adversarial inputs (empty, one point, sizes around the lane counts 4/8/16, NaN and infinite
// points, duplicates of the keypoint, zero and non-unit normals, points on the cylinder's border);
// refusals name the bad parameter; keypoints are the points nearest the voxels' centroids.
#include "kernels/spin_image.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "kernels/detail/spin_image_kernel.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr float NAN_F = std::numeric_limits<float>::quiet_NaN();
constexpr float INF_F = std::numeric_limits<float>::infinity();

struct Cloud {
  std::vector<float> x, y, z, nx, ny, nz;
  [[nodiscard]] ok::PointsView points() const { return {x, y, z}; }
  [[nodiscard]] ok::PointsView normals() const { return {nx, ny, nz}; }
  void add(float a, float b, float c, float na, float nb, float nc) {
    x.push_back(a);
    y.push_back(b);
    z.push_back(c);
    nx.push_back(na);
    ny.push_back(nb);
    nz.push_back(nc);
  }
  [[nodiscard]] std::size_t size() const { return x.size(); }
};

enum class Kind { RANDOM, ADVERSARIAL };

// A lumpy surface patch (points within a few centimetres of each other, so that most are
// neighbours at R = 5 cm) with unit normals; ADVERSARIAL adds NaN, infinite, duplicate points,
// zero and non-unit normals and points on the cylinder's border of the first keypoint.
Cloud make_cloud(std::size_t n, Kind kind, std::uint32_t seed, float border) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-0.05F, 0.05F);
  std::normal_distribution<float> normal(0.0F, 1.0F);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    float v[3] = {normal(rng), normal(rng), normal(rng) + 2.0F};
    const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const float px = coord(rng), py = coord(rng);
    c.add(px, py, 0.3F * (px * px - py * py) + 0.2F * coord(rng), v[0] / len, v[1] / len,
          v[2] / len);
    if (kind != Kind::ADVERSARIAL || i == 0) continue;
    switch (i % 9) {
      case 1:
        c.x[i] = NAN_F;
        break;
      case 2:
        c.z[i] = INF_F;
        break;
      case 3:  // a duplicate of point 0
        c.x[i] = c.x[0];
        c.y[i] = c.y[0];
        c.z[i] = c.z[0];
        break;
      case 4:
        c.nx[i] = c.ny[i] = c.nz[i] = 0.0F;
        break;
      case 5:
        c.nz[i] *= 3.0F;
        break;
      case 6:  // on the border of point 0's cylinder, along its normal (|beta| = limit)
        c.x[i] = c.x[0] + border * c.nx[0];
        c.y[i] = c.y[0] + border * c.ny[0];
        c.z[i] = c.z[0] + border * c.nz[0];
        break;
      case 7:
        c.nx[i] = NAN_F;
        break;
      default:
        break;
    }
  }
  return c;
}

std::vector<std::uint32_t> every_point(std::size_t n) {
  std::vector<std::uint32_t> k(n);
  for (std::size_t i = 0; i < n; ++i) k[i] = static_cast<std::uint32_t>(i);
  return k;
}

TEST(SpinImage, OneNeighbourComputedByHand) {
  // Keypoint at the origin, normal +z; W = 1, R = sqrt(2) * 0.1: bin 0.1. The neighbour at
  // (0.05, 0, 0.05): alpha 0.05, beta 0.05, cell (0, 1), a = b = 0.5: a quarter to each of the
  // four nodes (0, 1), (1, 1), (0, 2), (1, 2); the image sums to 1.
  Cloud c;
  c.add(0.0F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F);
  c.add(0.05F, 0.0F, 0.05F, 0.0F, 0.0F, 1.0F);
  ok::SpinImageParams p;
  p.image_width = 1;
  p.support_length = static_cast<float>(std::sqrt(2.0) * 0.1);
  std::vector<float> out(ok::spin_image_bins(1), -1.0F);
  const std::uint32_t key = 0;
  auto r = ok::spin_images(c.points(), c.normals(), {&key, 1}, p, out);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r.value(), 1U);
  const float want[6] = {0.0F, 0.25F, 0.25F, 0.0F, 0.25F, 0.25F};
  for (std::size_t b = 0; b < 6; ++b) EXPECT_NEAR(out[b], want[b], 1e-6F) << "bin " << b;
}

TEST(SpinImage, BelowTheTangentPlaneAndAtTheRim) {
  // W = 2, bin 0.1 (R = 0.2 sqrt 2): a neighbour 0.15 below the tangent plane on the axis (alpha
  // 0, beta -0.15: cell (0, 0), a = 0, b = 0.5) and one just inside the rim (alpha 0.19999, beta
  // 0: cell (1, 2), a ~ 1, b = 0); two neighbours, the image sums to 1.
  Cloud c;
  c.add(0.0F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F);
  c.add(0.0F, 0.0F, -0.15F, 0.0F, 0.0F, 1.0F);
  c.add(0.19999F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F);
  ok::SpinImageParams p;
  p.image_width = 2;
  p.support_length = static_cast<float>(std::sqrt(2.0) * 0.2);
  std::vector<float> out(ok::spin_image_bins(2));
  const std::uint32_t key = 0;
  ASSERT_EQ(ok::spin_images(c.points(), c.normals(), {&key, 1}, p, out).value(), 1U);
  // Columns: 5 (beta -0.2 .. 0.2 at 0.1 steps, column 2 = the tangent plane).
  EXPECT_NEAR(out[0 * 5 + 0], 0.25F, 1e-5F);  // (0, 0): (1 - a)(1 - b) / 2
  EXPECT_NEAR(out[0 * 5 + 1], 0.25F, 1e-5F);  // (0, 1): (1 - a) b / 2
  EXPECT_NEAR(out[2 * 5 + 2], 0.5F, 1e-4F);   // (2, 2): the rim point, a ~ 1
  float sum = 0.0F;
  for (float v : out) sum += v;
  EXPECT_NEAR(sum, 1.0F, 1e-6F);
}

TEST(SpinImage, ImagesWithoutWeightAreZerosAndNotCounted) {
  Cloud c;
  c.add(0.0F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F);   // alone within R: no neighbour
  c.add(1.0F, 0.0F, 0.0F, NAN_F, 0.0F, 1.0F);  // a keypoint without a normal
  c.add(1.0F, 0.0F, 0.01F, 0.0F, 0.0F, 1.0F);
  c.add(NAN_F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F);   // a keypoint that is not a point
  c.add(3.0F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F);    // its only neighbour is outside the cylinder
  c.add(3.0F, 0.0F, 0.049F, 0.0F, 0.0F, 1.0F);  // beta 0.049 >= W s = 0.05 / sqrt 2
  const std::vector<std::uint32_t> keys{0, 1, 3, 4};
  std::vector<float> out(keys.size() * ok::spin_image_bins(4), 7.0F);
  auto r = ok::spin_images(c.points(), c.normals(), keys, {}, out);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r.value(), 0U);
  for (float v : out) EXPECT_EQ(v, 0.0F);
}

TEST(SpinImage, RefusalsNameTheBadParameter) {
  Cloud c = make_cloud(20, Kind::RANDOM, 1, 0.0F);
  std::vector<float> out(20 * ok::spin_image_bins(16));
  const auto keys = every_point(20);
  using Code = ok::SpinImageError::Code;
  auto code = [&](ok::SpinImageParams p, ok::PointsView normals, std::span<const std::uint32_t> k,
                  std::span<float> o) {
    auto r = ok::spin_images(c.points(), normals, k, p, o);
    EXPECT_FALSE(r.has_value());
    EXPECT_FALSE(r.error().to_string().empty());
    return r.error().code;
  };
  ok::SpinImageParams p;
  p.image_width = 0;
  EXPECT_EQ(code(p, c.normals(), keys, out), Code::INVALID_WIDTH);
  p.image_width = 17;
  EXPECT_EQ(code(p, c.normals(), keys, out), Code::INVALID_WIDTH);
  p = {};
  p.support_length = NAN_F;
  EXPECT_EQ(code(p, c.normals(), keys, out), Code::INVALID_SUPPORT);
  p.support_length = -0.1F;
  EXPECT_EQ(code(p, c.normals(), keys, out), Code::INVALID_SUPPORT);
  p = {};
  p.support_angle_cos = 1.5F;
  EXPECT_EQ(code(p, c.normals(), keys, out), Code::INVALID_SUPPORT);
  const ok::PointsView short_normals{std::span(c.nx).first(5), std::span(c.ny).first(5),
                                     std::span(c.nz).first(5)};
  EXPECT_EQ(code({}, short_normals, keys, out), Code::NORMALS_SIZE);
  const std::uint32_t past = 20;
  EXPECT_EQ(code({}, c.normals(), {&past, 1}, out), Code::BAD_KEYPOINT);
  EXPECT_EQ(code({}, c.normals(), keys, std::span(out).first(19 * 45)), Code::OUTPUT_TOO_SMALL);
  auto r = ok::spin_images(c.points(), c.normals(), keys, {.image_width = 17}, out);
  EXPECT_NE(r.error().to_string().find("17"), std::string::npos) << r.error().to_string();
}

struct Case {
  std::uint32_t width;
  float support;
  float angle_cos;
};

class SpinImageTwins : public ::testing::TestWithParam<std::size_t> {};

TEST_P(SpinImageTwins, EverySimdVariantEqualsTheScalarTwinBitForBit) {
  const std::size_t n = GetParam();
  const Case cases[] = {{4, 0.05F, 0.0F}, {8, 0.1F, 0.0F}, {1, 0.03F, 0.5F}, {16, 0.08F, 0.9F}};
  for (const Kind kind : {Kind::RANDOM, Kind::ADVERSARIAL}) {
    for (const Case& k : cases) {
      const double limit = k.support / std::sqrt(2.0);
      const Cloud c = make_cloud(n, kind, static_cast<std::uint32_t>(n * 7 + k.width),
                                 static_cast<float>(limit));
      const auto keys = every_point(n);
      const ok::SpinImageParams p{k.width, k.support, k.angle_cos};
      const std::size_t bins = ok::spin_image_bins(k.width);
      std::vector<float> twin(n * bins), simd(n * bins);
      auto a = ok::spin_images_scalar(c.points(), c.normals(), keys, p, twin);
      auto b = ok::spin_images(c.points(), c.normals(), keys, p, simd);
      ASSERT_TRUE(a.has_value() && b.has_value());
      EXPECT_EQ(a.value(), b.value());
      EXPECT_TRUE(twin.empty() ||
                  std::memcmp(twin.data(), simd.data(), twin.size() * sizeof(float)) == 0)
          << "n " << n << " width " << k.width;
      if (kind == Kind::RANDOM && n >= 16) { EXPECT_GT(a.value(), 0U); }
      // Each compiled variant's neighbour search, keypoint by keypoint, against the twin's.
      const ok::detail::SpinSetup s = ok::detail::make_spin_setup(p);
      for (std::size_t i = 0; i < n; ++i) {
        const ok::detail::SpinKey key{c.x[i], c.y[i], c.z[i], c.nx[i], c.ny[i], c.nz[i]};
        std::vector<double> want(bins, 0.0);
        const std::size_t found =
            ok::detail::spin_range(s, key, c.points(), c.normals(), 0, n, want.data());
        ok::for_each_available_arch([&](auto arch) {
          std::vector<double> got(bins, 0.0);
          EXPECT_EQ(
              ok::detail::SpinNeighboursKernel{}(arch, s, key, c.points(), c.normals(), got.data()),
              found)
              << decltype(arch)::name();
          EXPECT_EQ(std::memcmp(want.data(), got.data(), bins * sizeof(double)), 0)
              << decltype(arch)::name() << " keypoint " << i;
        });
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, SpinImageTwins,
                         ::testing::Values(0, 1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 32, 33, 63,
                                           64, 65, 300));

TEST(VoxelKeypoints, ThePointNearestEachVoxelsCentroidOnce) {
  // Leaf 1: voxel (0,0,0) holds 0.1, 0.5, 0.9 on x (centroid 0.5: point 1); voxel (1,0,0) holds
  // 1.2 and 1.4 (centroid 1.3: a tie between points 3 and 4 at 0.1; the lower index, 3); a NaN
  // point is never chosen.
  Cloud c;
  for (float x : {0.1F, 0.5F, 0.9F, 1.2F, 1.4F}) c.add(x, 0.5F, 0.5F, 0.0F, 0.0F, 1.0F);
  c.add(NAN_F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F);
  ok::VoxelGridScratch scratch(c.size());
  Cloud centroids = make_cloud(c.size(), Kind::RANDOM, 3, 0.0F);
  const ok::PointsSpan cs{centroids.x, centroids.y, centroids.z};
  std::vector<std::uint32_t> keys(c.size(), 99);
  auto r = ok::voxel_keypoints(c.points(), 1.0F, scratch, cs, keys);
  ASSERT_TRUE(r.has_value()) << r.error().to_string();
  ASSERT_EQ(r.value(), 2U);
  EXPECT_EQ(keys[0], 1U);
  EXPECT_EQ(keys[1], 3U);
  auto bad = ok::voxel_keypoints(c.points(), 0.0F, scratch, cs, keys);
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.error().code, ok::VoxelGridError::Code::INVALID_LEAF);
  auto none = ok::voxel_keypoints({}, 0.01F, scratch, cs, keys);
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(none.value(), 0U);
}

}  // namespace
