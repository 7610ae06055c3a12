// Segmentation kernels, SIMD (dispatched) vs scalar twin across sizes (STYLE rule 5), plus the
// voxel grid and the grid clustering across sizes. Random points in a 2 m cube, 10 % NaN.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "kernels/crop.hpp"
#include "kernels/depth_projection.hpp"
#include "kernels/euclidean_cluster.hpp"
#include "kernels/plane_distance.hpp"
#include "kernels/voxel_grid.hpp"

namespace ok = orthoflow::kernels;

namespace {

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
};

Cloud make(std::size_t n) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> c(-1.0F, 1.0F);
  Cloud out;
  for (std::size_t i = 0; i < n; ++i) {
    out.x.push_back(i % 10 == 0 ? std::numeric_limits<float>::quiet_NaN() : c(rng));
    out.y.push_back(c(rng));
    out.z.push_back(c(rng) + 1.0F);
  }
  return out;
}

template <bool SIMD>
void BM_CropBox(benchmark::State& state) {
  const Cloud c = make(static_cast<std::size_t>(state.range(0)));
  std::vector<std::uint8_t> mask(c.x.size());
  const ok::AxisBox box{{-0.5F, -0.5F, 0.3F}, {0.5F, 0.5F, 1.5F}};
  for (auto _ : state) {
    benchmark::DoNotOptimize(SIMD ? ok::crop_box_mask(c.view(), box, mask) : ok::crop_box_mask_scalar(c.view(), box, mask));
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
    benchmark::DoNotOptimize(SIMD ? ok::depth_to_points(raw, 640, 480, table, {}, {x, y, z})
                                  : ok::depth_to_points_scalar(raw, 640, 480, table, {}, {x, y, z}));
  }
  state.SetItemsProcessed(state.iterations() * 640 * 480);
}

void BM_VoxelGrid(benchmark::State& state) {
  const Cloud c = make(static_cast<std::size_t>(state.range(0)));
  ok::VoxelGridScratch scratch(c.x.size());
  Cloud out = c;
  for (auto _ : state) { benchmark::DoNotOptimize(ok::voxel_grid(c.view(), 0.01F, scratch, {out.x, out.y, out.z})); }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_GridCluster(benchmark::State& state) {
  const Cloud c = make(static_cast<std::size_t>(state.range(0)));
  ok::ClusterScratch scratch(c.x.size());
  std::vector<std::int32_t> labels(c.x.size());
  for (auto _ : state) { benchmark::DoNotOptimize(ok::euclidean_cluster(c.view(), {}, {}, scratch, labels)); }
  state.SetItemsProcessed(state.iterations() * state.range(0));
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
BENCHMARK_MAIN();
