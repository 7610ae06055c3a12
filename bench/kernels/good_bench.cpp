// GOOD descriptor time: timing_5k.pcd (5,000 points) and a 50,000-point cloud (timing_5k repeated
// 10x with seeded 0.3 mm jitter), 5 and 15 bins, both modes, dispatched SIMD against the scalar
// twin, and the far-point check alone. Reference (testdata/good/timing/TIMING.txt, same machine
// kind): 0.37 ms at 5k, 3.9 ms at 50k.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "formats/pcd_io.hpp"
#include "kernels/far_points.hpp"
#include "kernels/good.hpp"
#include "kernels/simd_arch.hpp"

namespace ok = orthoflow::kernels;

namespace {

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
};

const Cloud& cloud(std::size_t copies) {
  static const Cloud base = [] {
    auto cloud_result =
        orthoflow::formats::read_pcd(ORTHOFLOW_SHARED_DIR "/testdata/good/timing/timing_5k.pcd");
    if (!cloud_result) {
      std::fprintf(stderr, "%s\n", cloud_result.error().to_string().c_str());
      std::exit(1);
    }
    const auto& pc = cloud_result.value();
    return Cloud{{pc.x().begin(), pc.x().end()},
                 {pc.y().begin(), pc.y().end()},
                 {pc.z().begin(), pc.z().end()}};
  }();
  static const Cloud big = [] {
    Cloud c;
    std::mt19937 rng(50000);
    std::uniform_real_distribution<float> jitter(-0.0003F, 0.0003F);
    for (int k = 0; k < 10; ++k) {
      for (std::size_t i = 0; i < base.x.size(); ++i) {
        c.x.push_back(base.x[i] + (k ? jitter(rng) : 0.0F));
        c.y.push_back(base.y[i] + (k ? jitter(rng) : 0.0F));
        c.z.push_back(base.z[i] + (k ? jitter(rng) : 0.0F));
      }
    }
    return c;
  }();
  return copies == 1 ? base : big;
}

// Args: copies (1 = 5k, 10 = 50k), bins, mode (0 invariant, 1 reference), simd (1) or scalar (0).
void BM_good(benchmark::State& state) {
  const Cloud& c = cloud(static_cast<std::size_t>(state.range(0)));
  const auto bins = static_cast<std::size_t>(state.range(1));
  const ok::GoodConfig cfg{
      bins, state.range(2) != 0 ? ok::GoodMode::REFERENCE : ok::GoodMode::INVARIANT, std::nullopt};
  const bool simd = state.range(3) != 0;
  ok::GoodScratch scratch(bins);
  std::vector<float> d(3 * bins * bins);
  for (auto _ : state) {
    auto r = simd ? ok::compute_good(c.view(), cfg, scratch, d)
                  : ok::compute_good_scalar(c.view(), cfg, scratch, d);
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(d.data());
  }
  state.counters["points"] = static_cast<double>(c.x.size());
  state.SetLabel(simd ? ok::simd_arch_name() : "scalar");
}

BENCHMARK(BM_good)
    ->ArgNames({"copies", "bins", "reference", "simd"})
    ->ArgsProduct({{1, 10}, {5, 15}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

// The far-point check compute_good() runs first (kernels/far_points.hpp), alone: its share of the
// BM_good time above. Args: copies.
void BM_find_far_points(benchmark::State& state) {
  const Cloud& c = cloud(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    const ok::FarPoints far = ok::find_far_points(c.view());
    benchmark::DoNotOptimize(far);
  }
  state.counters["points"] = static_cast<double>(c.x.size());
}

BENCHMARK(BM_find_far_points)->ArgNames({"copies"})->Arg(1)->Arg(10)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
