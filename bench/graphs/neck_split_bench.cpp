// The neck split's cost (kernels/neck_split.cpp, the crowded mode's last step): the product's chain
// (the embedded tabletop graph's parameters) with the split on and off, in the same run, on the 45
// mOSD learn-split frames (where it cuts nothing) and on seed 4's table of `orthoflow demo` (where
// it parts two touching cans); and the grid kernel alone on two touching discs.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/graph.hpp"
#include "formats/pcd_io.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/segment_params.hpp"
#include "graphs/sessions/table_task_session.hpp"
#include "kernels/detail/neck_scratch.hpp"
#include "kernels/segmentation_chain.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace {

namespace og = orthoflow::graphs;
namespace ok = orthoflow::kernels;

og::TabletopSegmentation tabletop(bool neck) {
  auto spec = orthoflow::engine::parse_graph(std::string(og::embedded_tabletop_yaml()), "tabletop");
  auto seg = og::segmentation_of_graph(*spec);
  if (!neck) seg->stages.crease.neck_cell = 0.0F;
  return *seg;
}

void run_chain(benchmark::State& state, const std::vector<ok::PointCloud>& clouds) {
  const auto seg = tabletop(state.range(0) != 0);
  std::size_t max_points = 0;
  for (const auto& c : clouds) max_points = std::max(max_points, c.size());
  ok::SegmentationChain chain(max_points, seg.stages, seg.candidates);
  std::size_t objects = 0;
  for (auto _ : state) {
    objects = 0;
    for (const auto& c : clouds) {
      auto result = chain.run(c.view());
      objects += result ? result->candidates.size() : 0;
      benchmark::DoNotOptimize(result);
    }
  }
  state.counters["frames"] = static_cast<double>(clouds.size());
  state.counters["objects"] = static_cast<double>(objects);
}

void BM_ChainOnMosdLearn(benchmark::State& state) {
  static const std::vector<ok::PointCloud> clouds = [] {
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(std::string(ORTHOFLOW_SHARED_DIR) +
                                                             "/data/mosd_learn"))
      files.push_back(e.path());
    std::sort(files.begin(), files.end());
    std::vector<ok::PointCloud> out;
    for (const auto& f : files)
      if (auto cloud = orthoflow::formats::read_pcd(f.string())) out.push_back(std::move(*cloud));
    return out;
  }();
  run_chain(state, clouds);
}
BENCHMARK(BM_ChainOnMosdLearn)->ArgName("neck")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_ChainOnDemoTable(benchmark::State& state) {
  static const std::vector<ok::PointCloud> clouds = [] {
    const auto scene = og::draw_task_table(og::TableTaskConfig{}, 4);
    orthoflow::core::Rng rng(4);
    std::vector<ok::PointCloud> out(1);
    orthoflow::simulation::render_scene(scene, {}, rng, out[0]);
    return out;
  }();
  run_chain(state, clouds);
}
BENCHMARK(BM_ChainOnDemoTable)->ArgName("neck")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_NeckPartsTwoDiscs(benchmark::State& state) {
  // Two touching discs of 7 cells (3.5 cm at 5 mm): a can pair's footprint.
  namespace od = orthoflow::kernels::detail;
  od::NeckScratch s;
  const std::size_t w = 40, h = 24;
  std::vector<std::uint8_t> disc(w * h, 0);
  for (std::size_t y = 2; y + 2 < h; ++y)
    for (std::size_t x = 2; x + 2 < w; ++x)
      disc[y * w + x] = std::hypot(double(x) - 11.0, double(y) - 12.0) <= 7.0 ||
                        std::hypot(double(x) - 25.0, double(y) - 12.0) <= 7.0;
  std::size_t parts = 0;
  for (auto _ : state) {
    std::copy(disc.begin(), disc.end(), s.cells.begin());
    parts = od::neck_parts(w, h, od::NeckRule{}, s);
    benchmark::DoNotOptimize(parts);
  }
  state.counters["parts"] = static_cast<double>(parts);
}
BENCHMARK(BM_NeckPartsTwoDiscs)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
