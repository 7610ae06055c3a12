// The kernels that only showed up inside the chain benchmarks: RANSAC plane (dispatched inlier
// counting vs the scalar twin), per-cluster statistics, and the PCA object frame (SIMD moments vs
// the scalar twin). Points: a noisy 1 m plane with 30 % clutter above it; clusters: 16 equal blobs.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "kernels/cluster_stats.hpp"
#include "kernels/organized_normals.hpp"
#include "kernels/pca_frame.hpp"
#include "kernels/ransac_plane.hpp"

namespace ok = orthoflow::kernels;

namespace {

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
};

Cloud table_scene(std::size_t n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.5F, 0.5F), h(0.0F, 0.3F);
  std::normal_distribution<float> noise(0.0F, 0.003F);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    c.x.push_back(u(rng));
    c.y.push_back(i % 10 < 3 ? -h(rng) : noise(rng));  // 30 % clutter above the plane y = 0
    c.z.push_back(1.0F + u(rng));
  }
  return c;
}

template <bool SIMD>
void BM_RansacPlane(benchmark::State& state) {
  const Cloud c = table_scene(static_cast<std::size_t>(state.range(0)));
  std::vector<std::uint32_t> inliers(c.x.size());
  const ok::RansacParams params;  // thesis: tau 0.02 m, 200 iterations
  for (auto _ : state) {
    auto plane = SIMD ? ok::ransac_plane(c.view(), params, inliers)
                      : ok::ransac_plane_scalar(c.view(), params, inliers);
    benchmark::DoNotOptimize(plane);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

/// A wall 1.5 m ahead (60 % of the points) and a level table 0.8 m below the camera (40 %): the
/// scene where the dominant plane is not the table (issue 50).
Cloud wall_and_table(std::size_t n) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0F, 1.0F), depth(0.5F, 1.45F);
  std::normal_distribution<float> noise(0.0F, 0.003F);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    const bool wall = i % 10 < 6;
    c.x.push_back(u(rng));
    c.y.push_back(wall ? 0.8F * u(rng) : 0.8F + noise(rng));
    c.z.push_back(wall ? 1.5F + noise(rng) : depth(rng));
  }
  return c;
}

/// RANSAC with and without the gravity prior (range(1) = 1: up known, hypotheses within 20 deg of
/// level) on wall_and_table: the counter `level` is 1 when the plane found is the table.
void BM_RansacGravityPrior(benchmark::State& state) {
  const Cloud c = wall_and_table(static_cast<std::size_t>(state.range(0)));
  std::vector<std::uint32_t> inliers(c.x.size());
  ok::RansacParams params;
  if (state.range(1) == 1) {
    params.up = {0.0F, -1.0F, 0.0F};
    params.max_tilt_deg = 20.0F;
  }
  bool level = false;
  for (auto _ : state) {
    auto plane = ok::ransac_plane(c.view(), params, inliers);
    level = plane.has_value() && -plane->plane.normal[1] > 0.98F;
    benchmark::DoNotOptimize(plane);
  }
  state.counters["level"] = level ? 1.0 : 0.0;
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_ClusterStats(benchmark::State& state) {
  const Cloud c = table_scene(static_cast<std::size_t>(state.range(0)));
  constexpr std::size_t CLUSTERS = 16;
  std::vector<std::int32_t> labels(c.x.size());
  for (std::size_t i = 0; i < labels.size(); ++i)
    labels[i] = static_cast<std::int32_t>(i % CLUSTERS);
  std::vector<ok::ClusterMoments> moments(CLUSTERS);
  std::vector<ok::ClusterStats> stats(CLUSTERS);
  for (auto _ : state) {
    benchmark::DoNotOptimize(ok::cluster_stats(c.view(), labels, moments, stats));
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

template <bool SIMD>
void BM_PcaFrame(benchmark::State& state) {
  const Cloud c = table_scene(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    auto frame = SIMD ? ok::compute_pca_frame(c.view()) : ok::compute_pca_frame_scalar(c.view());
    benchmark::DoNotOptimize(frame);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

}  // namespace

BENCHMARK(BM_RansacPlane<false>)->RangeMultiplier(8)->Range(512, 1 << 15);
BENCHMARK(BM_RansacPlane<true>)->RangeMultiplier(8)->Range(512, 1 << 15);
BENCHMARK(BM_RansacGravityPrior)->ArgsProduct({{4800, 19200}, {0, 1}});
BENCHMARK(BM_ClusterStats)->RangeMultiplier(8)->Range(512, 1 << 18);
BENCHMARK(BM_PcaFrame<false>)->RangeMultiplier(8)->Range(64, 1 << 16);
BENCHMARK(BM_PcaFrame<true>)->RangeMultiplier(8)->Range(64, 1 << 16);
BENCHMARK_MAIN();

namespace {

// organized_normals (the crowded mode): a 640 x H tilted plane with a bump, SIMD vs the scalar
// twin on the same grid in the same run (rows = state.range(0)).
struct NormalsGrid {
  std::vector<float> x, y, z, nx, ny, nz;
  std::uint32_t w = 640, h = 0;
};

NormalsGrid normals_grid(std::uint32_t rows) {
  NormalsGrid g;
  g.h = rows;
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t c = 0; c < g.w; ++c) {
      const float z = 1.0F + 0.0005F * float(r) + 0.01F * std::sin(0.05F * float(c));
      g.x.push_back((float(c) - 320.0F) * z / 525.0F);
      g.y.push_back((float(r) - float(rows) / 2) * z / 525.0F);
      g.z.push_back(z);
    }
  }
  g.nx.resize(g.x.size()), g.ny.resize(g.x.size()), g.nz.resize(g.x.size());
  return g;
}

template <bool Simd>
void BM_OrganizedNormals(benchmark::State& state) {
  NormalsGrid g = normals_grid(static_cast<std::uint32_t>(state.range(0)));
  const orthoflow::kernels::CloudView cloud{{g.x, g.y, g.z}, g.w, g.h};
  const orthoflow::kernels::PointsSpan out{g.nx, g.ny, g.nz};
  for (auto _ : state) {
    const std::size_t n = Simd ? orthoflow::kernels::organized_normals(cloud, {}, out)
                               : orthoflow::kernels::organized_normals_scalar(cloud, {}, out);
    benchmark::DoNotOptimize(n);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(g.x.size()));
}
BENCHMARK(BM_OrganizedNormals<false>)->Arg(120)->Arg(480);
BENCHMARK(BM_OrganizedNormals<true>)->Arg(120)->Arg(480);

}  // namespace
