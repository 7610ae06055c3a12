// kernels::SphereTargetFinder (the calibration ball, docs/MANIPULATION.md section 2) on one 640 x
// 480 frame of the simulated Kinect: the synthetic table with a 3 cm ball 0.9 m away (found), and
// the table alone (refused after the same votes and fits). Off the frame path: once per
// calibration pose.
#include <benchmark/benchmark.h>

#include "kernels/sphere_target.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace {

namespace ok = orthoflow::kernels;

ok::PointCloud frame(bool ball) {
  orthoflow::simulation::Scene scene;
  if (ball) scene.robot.push_back({{0.05, -0.1, 0.9}, {0.05, -0.1, 0.9}, 0.03});
  orthoflow::core::Rng rng(1);
  ok::PointCloud cloud;
  orthoflow::simulation::render_scene(scene, {}, rng, cloud);
  return cloud;
}

void BM_SphereTargetFind(benchmark::State& state) {
  const ok::PointCloud cloud = frame(state.range(0) != 0);
  ok::SphereTargetFinder finder(cloud.size());
  ok::SphereTargetParams params;
  params.radius = 0.03F;
  bool found = false;
  for (auto _ : state) {
    const auto result = finder.find(cloud.view(), params);
    found = result.has_value();
    benchmark::DoNotOptimize(result);
  }
  state.counters["found"] = found ? 1.0 : 0.0;
}
BENCHMARK(BM_SphereTargetFind)->ArgName("ball")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
