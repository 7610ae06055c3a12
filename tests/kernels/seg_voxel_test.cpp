// voxel_grid(): against a brute-force std::map reference (PCL's voxel rule), at any extent and
// leaf, every error code, determinism and ordering.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <vector>

#include "kernels/voxel_grid.hpp"

namespace ok = orthoflow::kernels;
using Code = ok::VoxelGridError::Code;

namespace {

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
  void add(float a, float b, float c) { x.push_back(a), y.push_back(b), z.push_back(c); }
};

struct Out {
  explicit Out(std::size_t n) : x(n), y(n), z(n) {}
  std::vector<float> x, y, z;
  ok::PointsSpan span() { return {x, y, z}; }
};

/// Reference: (iz, iy, ix) -> double sums, voxel index floor(float(p * (1/leaf))).
std::map<std::array<std::int64_t, 3>, std::array<double, 4>> reference(const Cloud& c, float leaf) {
  const float inv = 1.0F / leaf;
  std::map<std::array<std::int64_t, 3>, std::array<double, 4>> m;
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    if (!std::isfinite(c.x[i]) || !std::isfinite(c.y[i]) || !std::isfinite(c.z[i])) { continue; }
    auto& acc = m[{static_cast<std::int64_t>(std::floor(c.z[i] * inv)),
                   static_cast<std::int64_t>(std::floor(c.y[i] * inv)),
                   static_cast<std::int64_t>(std::floor(c.x[i] * inv))}];
    acc[0] += c.x[i], acc[1] += c.y[i], acc[2] += c.z[i], acc[3] += 1.0;
  }
  return m;
}

void expect_matches_reference(const Cloud& c, float leaf) {
  ok::VoxelGridScratch scratch(c.x.size());
  Out out(c.x.size());
  auto result = ok::voxel_grid(c.view(), leaf, scratch, out.span());
  ASSERT_TRUE(result) << result.error().to_string();
  const auto ref = reference(c, leaf);
  ASSERT_EQ(*result, ref.size());
  std::size_t k = 0;
  for (const auto& [key, acc] : ref) {  // map order == voxel order (z, y, x)
    EXPECT_FLOAT_EQ(out.x[k], static_cast<float>(acc[0] / acc[3])) << k;
    EXPECT_FLOAT_EQ(out.y[k], static_cast<float>(acc[1] / acc[3])) << k;
    EXPECT_FLOAT_EQ(out.z[k], static_cast<float>(acc[2] / acc[3])) << k;
    ++k;
  }
}

Cloud random_cloud(std::size_t n, float extent, std::uint32_t seed, float nan_share = 0.1F) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-extent, extent);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    c.add(coord(rng), coord(rng),
          unit(rng) < nan_share ? std::numeric_limits<float>::quiet_NaN() : coord(rng));
  }
  return c;
}

TEST(SegVoxel, MatchesReferenceAcrossSizesAndLeaves) {
  for (const std::size_t n : {1U, 2U, 5U, 16U, 17U, 1000U, 20000U}) {
    for (const float leaf : {0.005F, 0.05F, 0.3F, 5.0F}) {
      expect_matches_reference(random_cloud(n, 1.0F, std::uint32_t(n)), leaf);
    }
  }
}

TEST(SegVoxel, HugeExtentBeyondPclInt32) {
  // 2 km at 1 mm: 2e6 voxels per axis, 8e18 cells (PCL's int32 index overflows, issue #4365).
  expect_matches_reference(random_cloud(5000, 1000.0F, 3, 0.0F), 0.001F);
}

TEST(SegVoxel, GridBeyond64BitsUsesLexicographicOrder) {
  // 1e6 m at 1e-7 m: 2e13 voxels per axis, 8e39 cells: no packed 64-bit key exists.
  Cloud c = random_cloud(3000, 1e6F, 4, 0.0F);
  c.add(c.x[0], c.y[0], c.z[0]);  // a duplicate shares its voxel
  expect_matches_reference(c, 1e-7F);
}

TEST(SegVoxel, EmptyAllNanOnePointDuplicates) {
  expect_matches_reference(Cloud{}, 0.01F);
  Cloud nan_cloud = random_cloud(50, 1.0F, 5, 1.0F);
  expect_matches_reference(nan_cloud, 0.01F);
  Cloud one;
  one.add(0.25F, -3.0F, 7.5F);
  expect_matches_reference(one, 0.01F);
  Cloud dup;
  for (int i = 0; i < 40; ++i) { dup.add(0.1234F, 0.5F, -0.75F); }
  ok::VoxelGridScratch scratch(40);
  Out out(40);
  auto r = ok::voxel_grid(dup.view(), 0.01F, scratch, out.span());
  ASSERT_TRUE(r);
  EXPECT_EQ(*r, 1U);
  EXPECT_FLOAT_EQ(out.x[0], 0.1234F);
}

TEST(SegVoxel, DeterministicAndSortedByVoxel) {
  const Cloud c = random_cloud(4000, 0.5F, 6);
  ok::VoxelGridScratch scratch(c.x.size());
  Out a(c.x.size()), b(c.x.size());
  const std::size_t na = *ok::voxel_grid(c.view(), 0.02F, scratch, a.span());
  const std::size_t nb = *ok::voxel_grid(c.view(), 0.02F, scratch, b.span());
  ASSERT_EQ(na, nb);
  EXPECT_EQ(a.x, b.x);
  for (std::size_t k = 1; k < na; ++k) {
    EXPECT_LE(std::floor(a.z[k - 1] / 0.02F), std::floor(a.z[k] / 0.02F) + 1);
  }
}

TEST(SegVoxel, EveryErrorCode) {
  const Cloud c = random_cloud(100, 1.0F, 7);
  ok::VoxelGridScratch scratch(100);
  Out out(100);
  for (const float bad : {0.0F, -0.01F, std::numeric_limits<float>::quiet_NaN(),
                          std::numeric_limits<float>::infinity(), 1e-45F}) {
    auto r = ok::voxel_grid(c.view(), bad, scratch, out.span());
    ASSERT_FALSE(r) << bad;
    EXPECT_EQ(r.error().code, Code::INVALID_LEAF);
    EXPECT_NE(r.error().to_string().find("leaf"), std::string::npos);
  }
  Cloud far = c;
  far.add(3e30F, 0.0F, 0.0F);
  ok::VoxelGridScratch far_scratch(far.x.size());
  Out far_out(far.x.size());
  auto overflow = ok::voxel_grid(far.view(), 1e-10F, far_scratch, far_out.span());
  ASSERT_FALSE(overflow);
  EXPECT_EQ(overflow.error().code, Code::INDEX_OVERFLOW);
  ok::VoxelGridScratch small(10);
  auto scratch_small = ok::voxel_grid(c.view(), 0.1F, small, out.span());
  ASSERT_FALSE(scratch_small);
  EXPECT_EQ(scratch_small.error().code, Code::SCRATCH_TOO_SMALL);
  Out tiny(2);
  auto output_small = ok::voxel_grid(c.view(), 0.01F, scratch, tiny.span());
  ASSERT_FALSE(output_small);
  EXPECT_EQ(output_small.error().code, Code::OUTPUT_TOO_SMALL);
}

}  // namespace
