// The whole tabletop chain on the real mOSD Kinect frames: plane found, objects against the
// per-pixel ground truth (tests/kernels/seg_quality.hpp states the overlap rule), determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "formats/pcd_io.hpp"
#include "kernels/segmentation_chain.hpp"
#include "seg_quality.hpp"

namespace ok = orthoflow::kernels;

// Replacing the global new/delete with malloc/free is the standard-sanctioned way to count
// allocations; GCC's heuristic flags the (correct) free() inside the replacement operator delete.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
// Counts heap allocations while g_counting is set (the frame path must not allocate after warm-up).
namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::size_t> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
  }
  if (void* p = std::malloc(size == 0 ? 1 : size)) { return p; }
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

struct Frame {
  const char* name;
  std::size_t gt_objects;
  std::size_t min_matched;  // what the chain must detect at least (IoU >= 0.5)
};

class SegChainFrames : public ::testing::TestWithParam<Frame> {};

TEST_P(SegChainFrames, FindsTableAndObjects) {
  const Frame f = GetParam();
  auto cloud_result =
      orthoflow::formats::read_pcd(std::string(ORTHOFLOW_SHARED_DIR) + "/data/scenes/" + f.name);
  ASSERT_TRUE(cloud_result) << cloud_result.error().to_string();
  const ok::PointCloud& cloud = *cloud_result;
  ok::SegmentationChain chain(cloud.size(), ok::SegmentationParams{});
  auto seg_result = chain.run(cloud.view());
  ASSERT_TRUE(seg_result) << seg_result.error().to_string();
  const ok::SegmentationResult& seg = *seg_result;
  // The table faces the sensor: its normal points up toward -y/-z in the sensor frame, d > 0.
  EXPECT_GT(seg.plane.inliers, 1000U);
  EXPECT_LT(seg.plane.plane.normal[1], -0.5F);
  EXPECT_GT(seg.plane.plane.d, 0.3F);
  const auto q = orthoflow::testing::evaluate(cloud.label(), seg.labels);
  std::printf(
      "%s: plane n=(%.3f %.3f %.3f) d=%.3f inliers=%zu; gt %zu clusters %zu matched %zu precision "
      "%.2f "
      "recall %.2f over %zu under %zu; total %.2f ms\n",
      f.name, double(seg.plane.plane.normal[0]), double(seg.plane.plane.normal[1]),
      double(seg.plane.plane.normal[2]), double(seg.plane.plane.d), seg.plane.inliers, q.gt_objects,
      q.clusters, q.matched, q.precision(), q.recall(), q.over, q.under, seg.timings.total);
  std::printf("  ms: filter %.2f voxel %.2f plane %.2f prism %.2f cluster %.2f\n",
              seg.timings.filter, seg.timings.voxel, seg.timings.plane, seg.timings.prism,
              seg.timings.cluster);
  EXPECT_EQ(q.gt_objects, f.gt_objects);
  EXPECT_GE(q.matched, f.min_matched);
  EXPECT_EQ(seg.clusters.size(), q.clusters);
  // Deterministic: a second run gives the same labels, and allocates nothing.
  const std::vector<std::int32_t> first(seg.labels.begin(), seg.labels.end());
  g_allocations = 0;
  g_counting = true;
  auto again = chain.run(cloud.view());
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0U);
  ASSERT_TRUE(again);
  EXPECT_TRUE(std::equal(first.begin(), first.end(), again->labels.begin()));
}

TEST(SegChain, OrganizedStrideZeroRunsTheVoxelGrid) {
  // organized_stride = 0 puts the voxel grid (leaf) back in front of RANSAC on organized input;
  // both plane inputs give the same table within the tolerance and the same objects on
  // test31.
  auto cloud_result =
      orthoflow::formats::read_pcd(std::string(ORTHOFLOW_SHARED_DIR) + "/data/scenes/test31.pcd");
  ASSERT_TRUE(cloud_result) << cloud_result.error().to_string();
  const ok::PointCloud& cloud = *cloud_result;
  ok::SegmentationParams voxel_params;
  voxel_params.organized_stride = 0;
  ok::SegmentationChain strided(cloud.size(), ok::SegmentationParams{}),
      voxel(cloud.size(), voxel_params);
  auto a = strided.run(cloud.view());
  auto b = voxel.run(cloud.view());
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->timings.voxel, 0.0);  // no voxel grid on the strided path
  EXPECT_GT(b->timings.voxel, 0.0);
  EXPECT_GT(b->plane.inliers,
            4 * a->plane.inliers);  // voxels are about 4x denser than a stride-4 sample
  const auto& na = a->plane.plane.normal;
  const auto& nb = b->plane.plane.normal;
  EXPECT_GT(double(na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2]),
            std::cos(3.14159265358979 / 180.0));
  EXPECT_NEAR(a->plane.plane.d, b->plane.plane.d, 0.005F);
  const auto qa = orthoflow::testing::evaluate(cloud.label(), a->labels);
  const auto qb = orthoflow::testing::evaluate(cloud.label(), b->labels);
  EXPECT_EQ(qa.matched, qb.matched);
  EXPECT_GE(qa.matched, 2U);
}

TEST(SegChain, OrganizedSizeMismatchIsAnError) {
  std::vector<float> x(10, 1.0F), y(10, 0.0F), z(10, 1.0F);
  ok::SegmentationChain chain(16, ok::SegmentationParams{});
  auto seg = chain.run(ok::CloudView{{x, y, z}, 4, 4});  // 10 points for a 4 x 4 image
  ASSERT_FALSE(seg);
  EXPECT_NE(seg.error().to_string().find("10 points is not 4 x 4"), std::string::npos)
      << seg.error().to_string();
}

TEST(SegChain, SmallOrganizedFrameFitsOnTheFullSample) {
  // 80 x 60 pixels of a table at z = 1 m with a 12 x 12-pixel box 5 cm above it: the sample at
  // twice the stride has fewer than 500 points, so RANSAC runs on the stride-4 sample itself.
  const std::uint32_t w = 80, h = 60;
  std::vector<float> x, y, z;
  for (std::uint32_t v = 0; v < h; ++v) {
    for (std::uint32_t u = 0; u < w; ++u) {
      const bool box = u >= 30 && u < 42 && v >= 20 && v < 32;
      const float depth = box ? 0.95F : 1.0F;
      x.push_back((float(u) - 40.0F) * 0.004F), y.push_back((float(v) - 30.0F) * 0.004F),
          z.push_back(depth);
    }
  }
  ok::SegmentationParams params;
  params.cluster.min_size = 20;
  ok::SegmentationChain chain(x.size(), params);
  auto seg = chain.run(ok::CloudView{{x, y, z}, w, h});
  ASSERT_TRUE(seg) << seg.error().to_string();
  EXPECT_NEAR(seg->plane.plane.normal[2], -1.0F, 1e-4F);  // oriented toward the sensor: d > 0
  EXPECT_NEAR(seg->plane.plane.d, 1.0F, 1e-4F);
  EXPECT_EQ(seg->plane.inliers,
            300U - 9U);  // the 20 x 15 stride-4 sample minus the 3 x 3 on the box
  ASSERT_EQ(seg->clusters.size(), 1U);
  EXPECT_EQ(seg->clusters[0].points, 144U);
}

INSTANTIATE_TEST_SUITE_P(Mosd, SegChainFrames,
                         ::testing::Values(Frame{"test31.pcd", 3, 2}, Frame{"test44.pcd", 5, 2},
                                           Frame{"test55.pcd", 14, 8}),
                         [](const auto& p) { return std::string(p.param.name).substr(0, 6); });

}  // namespace
