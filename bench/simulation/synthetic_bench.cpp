// Synthetic Kinect frames: cost of rendering one 640x480 frame by object count, of one sequence
// frame (warm cloud, the allocation-free path) and of one segmented dataset view.
// Run: build/<preset>/bench/simulation/synthetic_bench --benchmark_min_time=0.3
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>

#include "simulation/world/object_dataset.hpp"
#include "simulation/world/synthetic_scene.hpp"
#include "simulation/world/synthetic_sequence.hpp"

namespace orthoflow::simulation {
namespace {

/// A full frame of a random scene with state.range(0) objects, rendered into a warm cloud.
void BM_RenderScene(benchmark::State& state) {
  SceneConfig config;
  config.objects = static_cast<std::uint32_t>(state.range(0));
  const Scene scene = make_scene(config, 6);  // a seed where ten objects fit
  kernels::PointCloud cloud;
  core::Rng rng(1);
  render_scene(scene, RenderOptions{}, rng, cloud);
  for (auto _ : state) {
    render_scene(scene, RenderOptions{}, rng, cloud);
    benchmark::DoNotOptimize(cloud.z().data());
  }
  state.counters["placed"] = static_cast<double>(scene.objects.size());
  state.counters["rays/s"] = benchmark::Counter(static_cast<double>(cloud.size()),
                                                benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RenderScene)->Arg(0)->Arg(5)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond);

/// One frame of the standard 6-object sequence (a mover, an appearing and a vanishing object).
void BM_SequenceFrame(benchmark::State& state) {
  const std::uint64_t frames = 1'000'000;
  SyntheticSequence seq(make_sequence_script(6, frames, 5), 2);
  kernels::PointCloud cloud;
  seq.next(cloud);
  for (auto _ : state) {
    if (!seq.next(cloud)) { state.SkipWithError("sequence ended"); }
    benchmark::DoNotOptimize(cloud.z().data());
  }
}
BENCHMARK(BM_SequenceFrame)->Unit(benchmark::kMillisecond);

/// One segmented view of a mug from 1 m (the dataset generator's inner loop, without the file
/// write).
void BM_DatasetView(benchmark::State& state) {
  const ObjectModel mug = make_object_model(Category::MUG, 0, 1);
  const ViewSpec view{45.0 * 3.14159265358979323846 / 180.0, 1.0, 1.0};
  kernels::PointCloud frame, out;
  core::Rng rng(1);
  std::size_t points = 0;
  for (auto _ : state) {
    points = render_object_view(mug, view, RenderOptions{}, rng, frame, out);
    benchmark::DoNotOptimize(out.z().data());
  }
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_DatasetView)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace orthoflow::simulation

BENCHMARK_MAIN();
