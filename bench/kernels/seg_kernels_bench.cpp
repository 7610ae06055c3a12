// Segmentation kernels, SIMD (dispatched) vs scalar twin across sizes (STYLE rule 5), plus the
// voxel grid and the grid clustering across sizes. Random points in a 2 m cube, 10 % NaN. The
// prism, the strided pixel sample and the organized clustering run on a synthetic 640 x 480
// tabletop frame.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bench/kernels/bench_cloud.hpp"
#include "kernels/crop.hpp"
#include "kernels/depth_projection.hpp"
#include "kernels/euclidean_cluster.hpp"
#include "kernels/pixel_subsample.hpp"
#include "kernels/plane_distance.hpp"
#include "kernels/polygonal_prism.hpp"
#include "kernels/voxel_grid.hpp"

namespace ok = orthoflow::kernels;

namespace {

using orthoflow::bench::Cloud;

Cloud make(std::size_t n) { return orthoflow::bench::random_cube(n, 1.0F, 1.0F); }

template <bool SIMD>
void BM_CropBox(benchmark::State& state) {
  const Cloud c = make(static_cast<std::size_t>(state.range(0)));
  std::vector<std::uint8_t> mask(c.x.size());
  const ok::AxisBox box{{-0.5F, -0.5F, 0.3F}, {0.5F, 0.5F, 1.5F}};
  for (auto _ : state) {
    benchmark::DoNotOptimize(SIMD ? ok::crop_box_mask(c.view(), box, mask)
                                  : ok::crop_box_mask_scalar(c.view(), box, mask));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

template <bool SIMD>
void BM_PlaneInliers(benchmark::State& state) {
  const Cloud c = make(static_cast<std::size_t>(state.range(0)));
  const ok::Plane plane{{0.0F, 0.6F, 0.8F}, -0.5F};
  for (auto _ : state) {
    benchmark::DoNotOptimize(SIMD ? ok::count_plane_inliers(c.view(), plane, 0.02F)
                                  : ok::count_plane_inliers_scalar(c.view(), plane, 0.02F));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

template <bool SIMD>
void BM_DepthToPoints(benchmark::State& state) {
  std::array<float, ok::DISPARITY_TABLE_SIZE> table{};
  ok::fill_disparity_table_reciprocal(table);
  std::mt19937 rng(2);
  std::vector<std::uint16_t> raw(640 * 480);
  for (auto& r : raw) { r = static_cast<std::uint16_t>(rng() % 8 == 0 ? 2047 : 500 + rng() % 500); }
  std::vector<float> x(raw.size()), y(raw.size()), z(raw.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(SIMD
                                 ? ok::depth_to_points(raw, 640, 480, table, {}, {x, y, z})
                                 : ok::depth_to_points_scalar(raw, 640, 480, table, {}, {x, y, z}));
  }
  state.SetItemsProcessed(state.iterations() * 640 * 480);
}

void BM_VoxelGrid(benchmark::State& state) {
  const Cloud c = make(static_cast<std::size_t>(state.range(0)));
  ok::VoxelGridScratch scratch(c.x.size());
  Cloud out = c;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ok::voxel_grid(c.view(), 0.01F, scratch, {out.x, out.y, out.z}));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_GridCluster(benchmark::State& state) {
  const Cloud c = make(static_cast<std::size_t>(state.range(0)));
  ok::ClusterScratch scratch(c.x.size());
  std::vector<std::int32_t> labels(c.x.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(ok::euclidean_cluster(c.view(), {}, {}, scratch, labels));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

/// 640 x 480 range image of a table (z = 1 m plane tilted) with 12 boxes of 6 x 6 cm standing on
/// it.
struct Frame {
  Cloud c;
  ok::Plane plane{{0.0F, -0.8F, -0.6F}, 0.6F};
};

Frame make_frame() {
  Frame f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> noise(-0.001F, 0.001F);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const float rx = (float(u) - 320.0F) / 525.0F, ry = (float(v) - 240.0F) / 525.0F;
      // Ray (rx, ry, 1) t meets -0.8 y - 0.6 z + 0.6 = 0 at t = 0.6 / (0.8 ry + 0.6).
      float t = 0.6F / (0.8F * ry + 0.6F);
      const bool object = (u / 40) % 3 == 1 && (v / 40) % 3 == 1 && v > 200;
      if (object) { t *= 0.95F; }  // in front of the table: above it
      const bool valid = t > 0.0F && t < 3.0F;
      f.c.x.push_back(valid ? rx * t : std::numeric_limits<float>::quiet_NaN());
      f.c.y.push_back(ry * t);
      f.c.z.push_back(t + noise(rng));
    }
  }
  return f;
}

template <bool SIMD>
void BM_PrismFrame(benchmark::State& state) {
  const Frame f = make_frame();
  const double hu[] = {-0.5, 0.5, 0.5, -0.5}, hv[] = {-0.3, -0.3, 0.6, 0.6};
  const ok::Prism prism{f.plane, ok::make_plane_basis(f.plane), hu, hv, 0.005F, 0.5F};
  std::vector<float> heights(f.c.x.size());
  std::vector<std::uint8_t> mask(f.c.x.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(SIMD ? ok::polygonal_prism(f.c.view(), prism, heights, mask)
                                  : ok::polygonal_prism_scalar(f.c.view(), prism, heights, mask));
  }
  state.SetItemsProcessed(state.iterations() * 640 * 480);
}

void BM_PixelSubsample(benchmark::State& state) {
  const Frame f = make_frame();
  Cloud out = f.c;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ok::pixel_subsample({f.c.view(), 640, 480},
                                                 static_cast<std::uint32_t>(state.range(0)),
                                                 ok::AxisBox{}, {out.x, out.y, out.z}));
  }
  state.SetItemsProcessed(state.iterations() * 640 * 480);
}

void BM_OrganizedCluster(benchmark::State& state) {
  const Frame f = make_frame();
  std::vector<float> heights(f.c.x.size());
  std::vector<std::uint8_t> mask(f.c.x.size());
  for (std::size_t i = 0; i < heights.size(); ++i) {  // the boxes: everything above the table
    const float h = f.plane.normal[1] * f.c.y[i] + f.plane.normal[2] * f.c.z[i] + f.plane.d;
    mask[i] = h > 0.005F ? 1 : 0;
  }
  ok::ClusterScratch scratch(f.c.x.size());
  std::vector<std::int32_t> labels(f.c.x.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        ok::euclidean_cluster_organized({f.c.view(), 640, 480}, mask, {}, scratch, labels));
  }
  state.SetItemsProcessed(state.iterations() * 640 * 480);
}

}  // namespace

BENCHMARK(BM_CropBox<false>)->RangeMultiplier(8)->Range(64, 1 << 19);
BENCHMARK(BM_CropBox<true>)->RangeMultiplier(8)->Range(64, 1 << 19);
BENCHMARK(BM_PlaneInliers<false>)->RangeMultiplier(8)->Range(64, 1 << 19);
BENCHMARK(BM_PlaneInliers<true>)->RangeMultiplier(8)->Range(64, 1 << 19);
BENCHMARK(BM_DepthToPoints<false>);
BENCHMARK(BM_DepthToPoints<true>);
BENCHMARK(BM_VoxelGrid)->RangeMultiplier(8)->Range(512, 1 << 18);
BENCHMARK(BM_GridCluster)->RangeMultiplier(8)->Range(512, 1 << 15);
BENCHMARK(BM_PrismFrame<false>);
BENCHMARK(BM_PrismFrame<true>);
BENCHMARK(BM_PixelSubsample)->Arg(1)->Arg(4);
BENCHMARK(BM_OrganizedCluster);
BENCHMARK_MAIN();
