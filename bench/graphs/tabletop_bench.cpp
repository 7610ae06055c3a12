// The tabletop graph end to end on recorded frames (STYLE rule 5): `orthoflow run`'s graph replays
// the 45 real mOSD learn-split frames (pcd_source, no pacing, one arena thread) and reports the
// per-frame latency (p50, p99) and the p50 of the three segmentation nodes; beside it, in the same
// run, the chain (kernels::SegmentationChain with the graph's parameters) once on each of the same
// frames, so that the ratio graph/chain says what the graph adds to the segmentation it runs.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "formats/pcd_io.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/segment_params.hpp"
#include "graphs/tabletop.hpp"

namespace {

namespace og = orthoflow::graphs;
namespace oe = orthoflow::engine;
namespace ok = orthoflow::kernels;

const std::string FRAMES = std::string(ORTHOFLOW_SHARED_DIR) + "/data/mosd_learn";

oe::GraphSpec spec_on_frames() {
  auto spec = oe::parse_graph(std::string(og::embedded_tabletop_yaml()), "tabletop.yaml");
  for (auto& node : spec->nodes) {
    if (node.name != "source") continue;
    node.kind = "pcd_source";
    node.params = {};
    node.params.assign("dir", FRAMES);
  }
  for (auto& node : spec->nodes) {
    if (node.kind == "recognise") node.params.assign("instructor", "0");
  }
  spec->period_ns = 0;
  return *spec;
}

double p50_us(const oe::NodeStats& n) {
  return static_cast<double>(n.service.percentile(0.5)) / 1e3;
}

void BM_TabletopGraphOnMosdFrames(benchmark::State& state) {
  const auto spec = spec_on_frames();
  double frame_p50 = 0, frame_p99 = 0, seg_p50 = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto learning = og::LearningService::open({});
    og::SessionLog log(nullptr);
    const auto registry = og::make_tabletop_registry(**learning, log);
    auto graph = oe::build_graph(spec, registry);
    if (!graph) {
      state.SkipWithError(oe::to_string(graph.error()).c_str());
      return;
    }
    oe::Engine engine(**graph, {1});
    state.ResumeTiming();
    engine.run({});
    state.PauseTiming();
    const auto& stats = engine.stats();
    frame_p50 = static_cast<double>(stats.frame_latency.percentile(0.5)) / 1e3;
    frame_p99 = static_cast<double>(stats.frame_latency.percentile(0.99)) / 1e3;
    seg_p50 = 0;
    for (const auto& n : stats.nodes) {
      if (n.name == "preprocess" || n.name == "table" || n.name == "objects") seg_p50 += p50_us(n);
    }
    state.ResumeTiming();
  }
  state.counters["frame_p50_us"] = frame_p50;
  state.counters["frame_p99_us"] = frame_p99;
  state.counters["segmentation_nodes_p50_us"] = seg_p50;
  state.counters["frames"] = 45;
}
BENCHMARK(BM_TabletopGraphOnMosdFrames)->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_ChainOnceOnEachMosdFrame(benchmark::State& state) {
  std::vector<ok::PointCloud> clouds;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(FRAMES)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    if (auto cloud = orthoflow::formats::read_pcd(f.string())) clouds.push_back(std::move(*cloud));
  }
  auto seg = og::segmentation_of_graph(spec_on_frames());
  std::size_t max_points = 0;
  for (const auto& c : clouds) max_points = std::max(max_points, c.size());
  ok::SegmentationChain chain(max_points, seg->stages, seg->candidates);
  for (auto _ : state) {
    for (const auto& c : clouds) {
      auto result = chain.run(c.view());
      benchmark::DoNotOptimize(result);
    }
  }
  state.counters["frames"] = static_cast<double>(clouds.size());
}
BENCHMARK(BM_ChainOnceOnEachMosdFrame)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
