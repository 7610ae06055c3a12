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

#include "engine/graph.hpp"
#include "evaluation/segmentation_eval.hpp"
#include "formats/pcd_io.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/segment_params.hpp"
#include "kernels/segmentation_chain.hpp"
#include "seg_quality.hpp"
#include "simulation/synthetic_scene.hpp"

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

namespace {

/// The tabletop graph's segmentation (graphs/tabletop.yaml, the product's chain), in either
/// clustering mode (Euclidean with the footprint merge it had before the crowded mode: 30 %).
orthoflow::graphs::TabletopSegmentation tabletop(ok::ClusterMode mode) {
  auto spec = orthoflow::engine::parse_graph(
      std::string(orthoflow::graphs::embedded_tabletop_yaml()), "tabletop.yaml");
  EXPECT_TRUE(spec);
  auto seg = orthoflow::graphs::segmentation_of_graph(*spec);
  EXPECT_TRUE(seg);
  EXPECT_EQ(seg->stages.cluster_mode, ok::ClusterMode::CROWDED);  // the default
  seg->stages.cluster_mode = mode;
  if (mode == ok::ClusterMode::EUCLIDEAN) seg->stages.merge_overlap = 0.3F;
  return *seg;
}

ok::SegmentationParams tabletop_params(ok::ClusterMode mode) { return tabletop(mode).stages; }

/// The product's objects (the candidates, as frame labels) scored against @p truth.
orthoflow::testing::Quality score_product(const ok::PointCloud& cloud,
                                          std::span<const std::uint32_t> truth,
                                          ok::ClusterMode mode) {
  const auto seg = tabletop(mode);
  const auto out = orthoflow::evaluation::make_chain_segmenter(seg.stages, seg.candidates)(cloud);
  EXPECT_TRUE(out.error.empty()) << out.error;
  if (!out.error.empty()) return {};
  const auto c = orthoflow::evaluation::score_objects(truth, out.labels);
  return {c.truth, c.predicted, c.matched, c.over, c.under};
}

/// Ground truth of a synthetic frame in the mOSD convention (object id k as label 10 (k + 2)).
std::vector<std::uint32_t> mosd_truth(const ok::PointCloud& cloud) {
  std::vector<std::uint32_t> truth;
  for (const std::uint32_t l : cloud.label()) {
    const int object = orthoflow::simulation::object_of_label(l);
    truth.push_back(object >= 0 ? static_cast<std::uint32_t>(object + 2) * 10U : 0U);
  }
  return truth;
}

orthoflow::testing::Quality segment_synthetic(const orthoflow::simulation::SceneConfig& config,
                                              std::uint64_t seed, ok::ClusterMode mode,
                                              std::size_t* placed = nullptr) {
  const auto scene = orthoflow::simulation::make_scene(config, seed);
  orthoflow::core::Rng rng(seed);
  ok::PointCloud cloud;
  orthoflow::simulation::render_scene(scene, {}, rng, cloud);
  if (placed != nullptr) *placed = scene.objects.size();
  return score_product(cloud, mosd_truth(cloud), mode);
}

}  // namespace

TEST(CrowdedMode, SeparatesStackedBoxesThatEuclideanClusteringMerges) {
  // Boxes in stacks of two (the generator's stacked mode): over ten scenes the crowded mode finds
  // more boxes than plain Euclidean clustering, which merges a box with the one it lies on, and
  // merges fewer. (A stack whose faces are flush leaves no crease: docs/SEGMENTATION.md.)
  orthoflow::simulation::SceneConfig config;
  config.objects = 6;
  config.stacked = true;
  std::size_t truth = 0, crowded = 0, euclidean = 0, under_crowded = 0, under_euclidean = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const auto c = segment_synthetic(config, seed, ok::ClusterMode::CROWDED);
    const auto e = segment_synthetic(config, seed, ok::ClusterMode::EUCLIDEAN);
    truth += c.gt_objects, crowded += c.matched, euclidean += e.matched;
    under_crowded += c.under, under_euclidean += e.under;
  }
  std::printf("stacked boxes: %zu objects, crowded %zu matched (%zu under), euclidean %zu (%zu)\n",
              truth, crowded, under_crowded, euclidean, under_euclidean);
  EXPECT_GE(double(crowded), 0.6 * double(truth));
  EXPECT_GE(crowded, euclidean + truth / 10);
  EXPECT_LT(under_crowded, under_euclidean);
}

TEST(CrowdedMode, TouchingObjectsAndSingleObjectsStayRight) {
  // Touching pairs (the generator's touching mode) and scenes of separate objects: the crowded
  // mode finds at least as many as Euclidean clustering and splits no more objects in two than it
  // does (a mug's handle stays on its mug, a bowl's inside on its outside).
  for (const bool touching : {true, false}) {
    orthoflow::simulation::SceneConfig config;
    config.objects = 8;
    config.touching = touching;
    std::size_t truth = 0, crowded = 0, euclidean = 0, over = 0, over_euclidean = 0;
    for (std::uint64_t seed = 20; seed < 30; ++seed) {
      const auto c = segment_synthetic(config, seed, ok::ClusterMode::CROWDED);
      const auto e = segment_synthetic(config, seed, ok::ClusterMode::EUCLIDEAN);
      truth += c.gt_objects, crowded += c.matched, euclidean += e.matched, over += c.over;
      over_euclidean += e.over;
    }
    std::printf("%s: %zu objects, crowded %zu matched (%zu over), euclidean %zu (%zu over)\n",
                touching ? "touching" : "apart", truth, crowded, over, euclidean, over_euclidean);
    EXPECT_GE(crowded, euclidean) << (touching ? "touching" : "apart");
    EXPECT_LE(over, over_euclidean) << (touching ? "touching" : "apart");
  }
}

TEST(CrowdedMode, SplitsARealStackAndAllocatesNothingWhenWarm) {
  // mOSD learn21: two boxes on a third: Euclidean clustering gives at most one right object, the
  // crowded mode at least two; a second run of the same frame allocates nothing and repeats
  // itself.
  auto cloud = orthoflow::formats::read_pcd(std::string(ORTHOFLOW_SHARED_DIR) +
                                            "/data/mosd_learn/learn21.pcd");
  ASSERT_TRUE(cloud) << cloud.error().to_string();
  const auto qa = score_product(*cloud, cloud->label(), ok::ClusterMode::CROWDED);
  const auto qb = score_product(*cloud, cloud->label(), ok::ClusterMode::EUCLIDEAN);
  EXPECT_EQ(qa.gt_objects, 3U);
  EXPECT_GE(qa.matched, 2U);
  EXPECT_LE(qb.matched, 1U);
  ok::SegmentationChain crowded(cloud->size(), tabletop_params(ok::ClusterMode::CROWDED));
  auto a = crowded.run(cloud->view());
  ASSERT_TRUE(a);
  const std::vector<std::int32_t> first(a->labels.begin(), a->labels.end());
  g_allocations = 0;
  g_counting = true;
  auto again = crowded.run(cloud->view());
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0U);
  ASSERT_TRUE(again);
  EXPECT_TRUE(std::equal(first.begin(), first.end(), again->labels.begin()));
}

TEST(CrowdedMode, UnorganizedCloudsFallBackToEuclidean) {
  auto cloud = orthoflow::formats::read_pcd(std::string(ORTHOFLOW_SHARED_DIR) +
                                            "/data/mosd_learn/learn0.pcd");
  ASSERT_TRUE(cloud);
  ok::PointCloud flat;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    if (!std::isfinite(cloud->z()[i])) continue;
    flat.resize_unorganized(flat.size() + 1);
    flat.x().back() = cloud->x()[i], flat.y().back() = cloud->y()[i],
    flat.z().back() = cloud->z()[i];
  }
  ok::SegmentationChain a(flat.size(), tabletop_params(ok::ClusterMode::CROWDED));
  ok::SegmentationChain b(flat.size(), tabletop_params(ok::ClusterMode::EUCLIDEAN));
  auto ra = a.run(flat.view());
  auto rb = b.run(flat.view());
  ASSERT_TRUE(ra && rb);
  ASSERT_EQ(ra->clusters.size(), rb->clusters.size());
  EXPECT_TRUE(std::equal(ra->labels.begin(), ra->labels.end(), rb->labels.begin()));
}

namespace {

/// A 320 x 240 view of a table 1 m away, tilted 50 degrees, whose pixels inside a rectangle
/// covering @p share of them see the top of a large box 8 cm above it instead (a face parallel to
/// the table: the misleading sample of issue 17).
ok::PointCloud table_with_plateau(double share) {
  const double tilt = 50.0 * 3.14159265358979 / 180.0;
  const double ny = -std::cos(tilt), nz = -std::sin(tilt);  // normal toward the sensor
  const double d_table = 1.0 * std::sin(tilt);              // table through (0, 0, 1)
  ok::PointCloud cloud;
  cloud.resize(320, 240);
  const double side = std::sqrt(share);
  for (std::uint32_t r = 0; r < 240; ++r) {
    for (std::uint32_t c = 0; c < 320; ++c) {
      const bool on_box = std::fabs(double(c) - 160.0) < 160.0 * side &&
                          std::fabs(double(r) - 120.0) < 120.0 * side;
      const double d = on_box ? d_table - 0.08 : d_table;  // the box top: 8 cm toward the sensor
      const double rx = (double(c) - 160.0) / 262.5, ry = (double(r) - 120.0) / 262.5;
      const double t = -d / (ny * ry + nz);
      const std::size_t i = std::size_t{r} * 320 + c;
      cloud.x()[i] = float(rx * t), cloud.y()[i] = float(ry * t), cloud.z()[i] = float(t);
    }
  }
  return cloud;
}

}  // namespace

TEST(TablePlane, ALargeFaceParallelToTheTableStillGivesTheTable) {
  // The box top holds 60 % of the pixels, so RANSAC's best plane is the box top; the table stage
  // finds the level 8 cm below it among the other points and takes it (PlaneCheck::switched).
  const ok::PointCloud cloud = table_with_plateau(0.6);
  ok::SegmentationChain chain(cloud.size(), tabletop_params(ok::ClusterMode::CROWDED));
  auto seg = chain.run(cloud.view());
  ASSERT_TRUE(seg) << seg.error().to_string();
  const double d_table = std::sin(50.0 * 3.14159265358979 / 180.0);
  EXPECT_NEAR(seg->plane.plane.d, d_table, 0.003);
  EXPECT_TRUE(seg->plane_check.switched);
  EXPECT_GT(seg->plane_check.near_share, 0.99F);
  // A box top of 20 % is not the dominant plane: the table comes first and stays.
  const ok::PointCloud small = table_with_plateau(0.2);
  auto seg_small = chain.run(small.view());
  ASSERT_TRUE(seg_small);
  EXPECT_NEAR(seg_small->plane.plane.d, d_table, 0.003);
  EXPECT_FALSE(seg_small->plane_check.switched);
}

TEST(TablePlane, TheFloorBelowALargeViewOfItIsNotTheTable) {
  // Synthetic seed 22 (8 objects apart, table 1.2 m away at 34 degrees): the floor 0.69 m below
  // fills more of the view than the table; the table stage takes the table above it.
  orthoflow::simulation::SceneConfig config;
  config.objects = 8;
  const auto scene = orthoflow::simulation::make_scene(config, 22);
  orthoflow::core::Rng rng(22);
  ok::PointCloud cloud;
  orthoflow::simulation::render_scene(scene, {}, rng, cloud);
  ok::SegmentationChain chain(cloud.size(), tabletop_params(ok::ClusterMode::CROWDED));
  auto seg = chain.run(cloud.view());
  ASSERT_TRUE(seg) << seg.error().to_string();
  const auto frame = orthoflow::simulation::table_frame(scene.table);
  EXPECT_NEAR(seg->plane.plane.d, frame.d, 0.01);
  EXPECT_TRUE(seg->plane_check.switched);
  EXPECT_GE(seg->candidates.size(), 6U);
}
