// Frame-to-labels latency of the product (issue 17, goal 5): the embedded tabletop graph (the one
// `orthoflow run` runs: crowded-mode segmentation, tracking, GOOD, recognition; instructor off) on
// ONE arena thread, unpaced with one frame in flight (so a frame's latency is its own work, not a
// queue behind earlier frames, as when a camera's frames arrive slower than they are processed), on
// pre-decoded frames (pcd_source decodes ahead on its own thread;
// synthetic frames are rendered before their stamp), reporting the engine's frame latency (source
// stamp -> frame fully processed) p50 / p99 / p99.9 / max and the frames over 33.3 ms (a 30 Hz
// deadline); beside it, in the same run, PCL 1.13's classic chain (specs/BASELINES.md) on the same
// frames, timed per frame. Inputs: the 45 mOSD learn-split frames, the same frames unorganized (the
// NaN pixels dropped, HEIGHT 1, as ROS bags store them), synthetic sequences with 3, 10, 16 and 30
// objects, and the hostile inputs of issue 50 (tests/support/hostile_frames.hpp: sensor noise, a
// wall, no reading, a hand at the lens, a person at a desk, a heap of 60 objects). Per input it
// also reports the objects and track nodes' p99 and the objects node's budget counters
// (degraded_*). Usage: graph_latency_vs_pcl [--frames N] (synthetic frames per input, default 300;
// PCL runs on the first 30 of them) plus Google Benchmark flags.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "bench/vs_pcl/pcl_chain.hpp"
#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "formats/pcd_io.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/tabletop.hpp"
#include "simulation/world/synthetic_sequence.hpp"
#include "tests/support/hostile_frames.hpp"
#include "tests/support/unorganized_copy.hpp"

namespace {

namespace og = orthoflow::graphs;
namespace oe = orthoflow::engine;
namespace ok = orthoflow::kernels;
namespace fs = std::filesystem;

std::uint64_t g_synthetic_frames = 300;
std::uint64_t g_hostile_frames = 40;
constexpr std::size_t PCL_SYNTHETIC_FRAMES = 30;
constexpr double DEADLINE_MS = 1000.0 / 30.0;

oe::GraphSpec spec_with_source(const std::string& kind,
                               const std::vector<std::pair<std::string, std::string>>& params) {
  auto spec = oe::parse_graph(std::string(og::embedded_tabletop_yaml()), "tabletop.yaml");
  for (auto& node : spec->nodes) {
    if (node.name == "source") {
      node.kind = kind;
      node.params = {};
      for (const auto& [k, v] : params) node.params.assign(k, v);
    }
    if (node.kind == "recognise") node.params.assign("instructor", "0");
  }
  spec->period_ns = 0;
  spec->max_in_flight = 1;  // one frame at a time: its latency is its own, not a queue's
  return *spec;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * double(v.size())))];
}

/// Runs @p spec on one thread; fills the graph counters.
void run_graph(benchmark::State& state, const oe::GraphSpec& spec) {
  auto learning = og::LearningService::open({});
  og::SessionLog log(nullptr);
  const auto registry = og::make_tabletop_registry(**learning, log);
  auto graph = oe::build_graph(spec, registry);
  if (!graph) {
    state.SkipWithError(oe::to_string(graph.error()).c_str());
    return;
  }
  oe::Engine engine(**graph, {1});
  engine.run({});
  const auto& lat = engine.stats().frame_latency;
  auto ms = [](std::int64_t ns) { return double(ns) / 1e6; };
  state.counters["graph_p50_ms"] = ms(lat.percentile(0.5));
  state.counters["graph_p99_ms"] = ms(lat.percentile(0.99));
  state.counters["graph_p999_ms"] = ms(lat.percentile(0.999));
  state.counters["graph_max_ms"] = ms(lat.max());
  state.counters["frames"] = double(lat.count());
  for (const auto& node : engine.stats().nodes) {
    if (node.name == "objects" || node.name == "track") {
      state.counters[node.name + "_p99_ms"] = ms(node.service.percentile(0.99));
    }
    if (!node.device || std::string_view(node.counter_group) != "budget") continue;
    std::array<oe::DeviceCounter, oe::MAX_DEVICE_COUNTERS> counters{};
    const std::size_t n = node.device(counters);
    for (std::size_t k = 0; k < n; ++k) {
      state.counters[std::string("degraded_") + counters[k].name] = double(counters[k].value);
    }
  }
  std::size_t over = 0;  // the histogram's buckets do not give an exact count; the max bounds it
  over = lat.max() > static_cast<std::int64_t>(DEADLINE_MS * 1e6) ? 1 : 0;
  state.counters["max_over_33ms"] = double(over);  // 0: no frame missed a 30 Hz deadline
}

/// PCL's chain once on each cloud, per-frame times.
void run_pcl(benchmark::State& state, const std::vector<ok::PointCloud>& clouds) {
  std::vector<double> t;
  for (const auto& c : clouds) {
    const auto pcl_cloud = orthoflow::bench::to_pcl(c);
    t.push_back(orthoflow::bench::run_pcl_chain(pcl_cloud).t.total);
  }
  state.counters["pcl_p50_ms"] = percentile(t, 0.5);
  state.counters["pcl_p99_ms"] = percentile(t, 0.99);
  const double g = state.counters["graph_p50_ms"];
  state.counters["pcl_over_graph_p50"] = g > 0 ? percentile(t, 0.5) / g : 0.0;
}

std::vector<fs::path> learn_files() {
  std::vector<fs::path> files;
  for (const auto& e :
       fs::directory_iterator(std::string(ORTHOFLOW_SHARED_DIR) + "/data/mosd_learn")) {
    if (e.path().extension() == ".pcd") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// The learn split, or its unorganized copies (written once into a temporary folder).
fs::path frames_dir(bool unorganized, std::vector<ok::PointCloud>& clouds) {
  const fs::path tmp =
      fs::temp_directory_path() / ("orthoflow_unorganized_" + std::to_string(::getpid()));
  if (unorganized) fs::create_directories(tmp);
  for (const auto& f : learn_files()) {
    auto c = orthoflow::formats::read_pcd(f);
    if (!c) continue;
    if (!unorganized) {
      clouds.push_back(std::move(*c));
      continue;
    }
    ok::PointCloud flat = orthoflow::test::unorganized_copy(*c);
    (void)orthoflow::formats::write_pcd(flat, tmp / f.filename());
    clouds.push_back(std::move(flat));
  }
  return unorganized ? tmp : fs::path(std::string(ORTHOFLOW_SHARED_DIR) + "/data/mosd_learn");
}

void BM_LearnSplit(benchmark::State& state, bool unorganized) {
  std::vector<ok::PointCloud> clouds;
  const fs::path dir = frames_dir(unorganized, clouds);
  for (auto _ : state) {
    run_graph(state, spec_with_source("pcd_source", {{"dir", dir.string()}}));
    run_pcl(state, clouds);
  }
  if (unorganized) fs::remove_all(dir);
}

void BM_Synthetic(benchmark::State& state, std::uint32_t objects) {
  const std::uint64_t seed = 1000 + objects;
  std::vector<ok::PointCloud> clouds;
  orthoflow::simulation::SyntheticSequence sequence(
      orthoflow::simulation::make_sequence_script(objects, g_synthetic_frames, seed), seed);
  for (std::size_t k = 0; k < PCL_SYNTHETIC_FRAMES; ++k) {
    ok::PointCloud c;
    if (!sequence.next(c)) break;
    clouds.push_back(std::move(c));
  }
  for (auto _ : state) {
    run_graph(state,
              spec_with_source("synthetic_source", {{"seed", std::to_string(seed)},
                                                    {"frames", std::to_string(g_synthetic_frames)},
                                                    {"objects", std::to_string(objects)}}));
    run_pcl(state, clouds);
  }
}

/// An input of tests/support/hostile_frames.hpp: its frames written once into a temporary folder
/// and replayed by pcd_source; PCL on the same frames.
void BM_Hostile(benchmark::State& state, orthoflow::test::Hostile input) {
  const fs::path dir =
      fs::temp_directory_path() / ("orthoflow_hostile_" + std::to_string(::getpid()) + "_" +
                                   std::string(orthoflow::test::hostile_name(input)));
  fs::create_directories(dir);
  std::vector<ok::PointCloud> clouds;
  for (std::uint64_t k = 0; k < g_hostile_frames; ++k) {
    ok::PointCloud c = orthoflow::test::hostile_frame(input, 50, k);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04llu.pcd", static_cast<unsigned long long>(k));
    (void)orthoflow::formats::write_pcd(c, dir / name);
    if (clouds.size() < PCL_SYNTHETIC_FRAMES) clouds.push_back(std::move(c));
  }
  for (auto _ : state) {
    run_graph(state, spec_with_source("pcd_source", {{"dir", dir.string()}}));
    run_pcl(state, clouds);
  }
  fs::remove_all(dir);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      g_synthetic_frames = std::max<std::uint64_t>(1, std::strtoull(argv[++i], nullptr, 10));
    } else {
      rest.push_back(argv[i]);
    }
  }
  int n = static_cast<int>(rest.size());
  benchmark::RegisterBenchmark("graph_vs_pcl/mosd_learn_organized", BM_LearnSplit, false)
      ->Iterations(1)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("graph_vs_pcl/mosd_learn_unorganized", BM_LearnSplit, true)
      ->Iterations(1)
      ->Unit(benchmark::kMillisecond);
  for (const auto input : orthoflow::test::HOSTILE_INPUTS) {
    benchmark::RegisterBenchmark(
        ("graph_vs_pcl/" + std::string(orthoflow::test::hostile_name(input))).c_str(), BM_Hostile,
        input)
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
  }
  for (const std::uint32_t objects : {3U, 10U, 16U, 30U}) {
    benchmark::RegisterBenchmark(("graph_vs_pcl/synthetic_" + std::to_string(objects)).c_str(),
                                 BM_Synthetic, objects)
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&n, rest.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
