// One query against N stored 675-value (15-bin GOOD) descriptors, N = 100, 1k, 10k, 100k, every
// metric, dispatched SIMD against the scalar twin; and the 10 nearest neighbours.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "kernels/distance.hpp"
#include "kernels/simd_arch.hpp"

namespace ok = orthoflow::kernels;

namespace {

constexpr std::size_t DIMS = 675;

// Largest store once (270 MB at 100k); smaller N use its first columns with the same stride.
const std::vector<float>& store() {
  static const std::vector<float> data = [] {
    std::vector<float> v(DIMS * 100000);
    std::mt19937 rng(675);
    std::uniform_real_distribution<float> u(0.0F, 0.003F);
    for (float& x : v) { x = u(rng); }
    return v;
  }();
  return data;
}

std::vector<float> query() {
  std::vector<float> q(DIMS);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0F, 0.003F);
  for (float& x : q) { x = u(rng); }
  return q;
}

// Args: N, metric, simd (1) or scalar (0).
void BM_distances(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const auto metric = static_cast<ok::Metric>(state.range(1));
  const bool simd = state.range(2) != 0;
  const ok::DescriptorMatrixView s{store(), DIMS, n, 100000};
  const std::vector<float> q = query();
  std::vector<float> out(n);
  for (auto _ : state) {
    const std::size_t w =
        simd ? ok::distances(q, s, metric, out) : ok::distances_scalar(q, s, metric, out);
    benchmark::DoNotOptimize(w);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetLabel(std::string(ok::to_string(metric)) +
                 (simd ? std::string(" ") + ok::simd_arch_name() : " scalar"));
  state.counters["descriptors/s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK(BM_distances)
    ->ArgNames({"n", "metric", "simd"})
    ->ArgsProduct({{100, 1000, 10000, 100000}, {0, 1, 3, 4, 5}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

void BM_nearest10(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const ok::DescriptorMatrixView s{store(), DIMS, n, 100000};
  const std::vector<float> q = query();
  std::vector<float> scratch(n);
  std::vector<ok::Neighbor> out(10);
  for (auto _ : state) {
    benchmark::DoNotOptimize(ok::nearest_k(q, s, ok::Metric::L1, scratch, out));
  }
}

BENCHMARK(BM_nearest10)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
