// capsule_mask (the robot-body filter's kernel), SIMD (dispatched) vs scalar twin (STYLE rule 5):
// a full 640 x 480 frame (307,200 points, 10 % NaN) in front of the camera and the 7 capsules of
// the JACO2's link model, and a size sweep. The per-frame cost of the body filter is the 307,200
// point case.
#include <benchmark/benchmark.h>

#include <vector>

#include "bench/kernels/bench_cloud.hpp"
#include "kernels/capsule_mask.hpp"

namespace ok = orthoflow::kernels;

namespace {

using orthoflow::bench::Cloud;

Cloud make(std::size_t n) { return orthoflow::bench::random_cube(n, 0.8F, 1.2F); }

// An arm reaching into the view: a base column, upper arm, elbow, forearm, two wrist links, hand.
const std::vector<ok::Capsule> ARM = {{{0.0F, 0.5F, 1.9F}, {0.0F, 0.3F, 1.7F}, 0.075F},
                                      {{0.0F, 0.3F, 1.7F}, {0.2F, 0.0F, 1.5F}, 0.065F},
                                      {{0.2F, 0.0F, 1.5F}, {0.21F, 0.0F, 1.49F}, 0.065F},
                                      {{0.21F, 0.0F, 1.49F}, {0.1F, 0.1F, 1.3F}, 0.06F},
                                      {{0.1F, 0.1F, 1.3F}, {0.08F, 0.15F, 1.25F}, 0.06F},
                                      {{0.08F, 0.15F, 1.25F}, {0.05F, 0.2F, 1.15F}, 0.06F},
                                      {{0.06F, 0.17F, 1.2F}, {0.04F, 0.25F, 1.08F}, 0.08F}};

template <bool SIMD>
void BM_CapsuleMask(benchmark::State& state) {
  const Cloud c = make(static_cast<std::size_t>(state.range(0)));
  std::vector<std::uint8_t> mask(c.x.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(SIMD ? ok::capsule_mask(c.view(), ARM, mask)
                                  : ok::capsule_mask_scalar(c.view(), ARM, mask));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

}  // namespace

BENCHMARK(BM_CapsuleMask<false>)->Name("BM_CapsuleMask/scalar")->Arg(1024)->Arg(32768)->Arg(307200);
BENCHMARK(BM_CapsuleMask<true>)->Name("BM_CapsuleMask/simd")->Arg(1024)->Arg(32768)->Arg(307200);
BENCHMARK_MAIN();
