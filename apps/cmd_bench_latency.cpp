// `orthoflow bench latency [--graph FILE] [--source synthetic:SEED|pcd:DIR] [--frames N]
// [--rate HZ|max] [--threads N] [--stress LOAD] [--json FILE] [--plot FILE.png]`: latency
// benchmarking on the user's own robot PC, the way cyclictest is run: the graph runs on its source
// (paced at the graph's period by default, which is each frame's deadline), optionally beside a CPU
// stress load (one thread per core, each busy LOAD of every 10 ms), and the command reports the
// frame-to-labels latency (source stamp -> frame fully processed) at p50, p90, p99, p99.9, p99.99
// and max, the deadline misses, every node's tails (engine telemetry), and the machine, kernel,
// compiler, flags and SIMD level it ran on: as text, as JSON (--json) and as a percentile plot
// (--plot). Learning runs in memory; the instructor of a synthetic session is off (teaching is not
// frame work). Percentiles are exact (every frame's latency is kept: RunOptions::latency_trace) up
// to 2 million frames; past that they come from the engine's log-bucket histogram, at most 12.5 %
// above the true value (max stays exact). The output says which.
#include <sys/utsname.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "apps/commands.hpp"
#include "apps/graph_overrides.hpp"
#include "core/file_output.hpp"
#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "engine/histogram.hpp"
#include "evaluation/line_plot.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/descriptor_params.hpp"
#include "graphs/tabletop.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::apps {
namespace {

constexpr std::uint64_t EXACT_FRAMES_UP_TO =
    2'000'000;  ///< exact percentiles up to this many frames

struct BenchArgs {
  std::string graph, source, rate, json, plot;
  std::uint64_t frames = 300;
  int threads = 1;
  double stress = 0.0;
};

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow bench latency: " << message << '\n';
  throw CLI::RuntimeError(code);
}

/// One busy thread per core: each spins for load x 10 ms, then sleeps the rest of the 10 ms.
class StressLoad {
 public:
  explicit StressLoad(double load) {
    if (load <= 0.0) return;
    const unsigned cores = std::max(1U, std::thread::hardware_concurrency());
    for (unsigned k = 0; k < cores; ++k) {
      threads_.emplace_back([this, load] {
        using Clock = std::chrono::steady_clock;
        const auto busy = std::chrono::duration<double, std::milli>(10.0 * load);
        const auto idle = std::chrono::duration<double, std::milli>(10.0 * (1.0 - load));
        volatile std::uint64_t sink = 0;
        while (!stop_.load(std::memory_order_relaxed)) {
          const auto until = Clock::now() + busy;
          while (Clock::now() < until) sink = sink + 1;
          if (idle.count() > 0) std::this_thread::sleep_for(idle);
        }
      });
    }
  }
  ~StressLoad() {
    stop_.store(true);
    for (auto& t : threads_) t.join();
  }
  StressLoad(const StressLoad&) = delete;
  StressLoad& operator=(const StressLoad&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("model name", 0) == 0 || line.rfind("Model", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "unknown";
}

nlohmann::json machine_json(const BenchArgs& a) {
  utsname u{};
  (void)uname(&u);
  return {{"cpu", cpu_model()},
          {"cores", std::thread::hardware_concurrency()},
          {"kernel", std::string(u.sysname) + " " + u.release},
          {"arch", u.machine},
          {"simd", kernels::simd_arch_name()},
          {"compiler", __VERSION__},
          {"flags", ORTHOFLOW_CXX_FLAGS},
          {"threads", a.threads},
          {"stress", a.stress}};
}

void run_bench(const BenchArgs& a) {
  auto spec = a.graph.empty() ? engine::parse_graph(std::string(graphs::embedded_tabletop_yaml()),
                                                    "embedded:tabletop.yaml")
                              : engine::load_graph_file(a.graph);
  if (!spec) fail(engine::to_string(spec.error()), EXIT_BAD_INPUT);
  if (auto ok = apply_source(*spec, a.source, a.frames); !ok) fail(ok.error(), EXIT_USAGE);
  apply_rate(*spec, a.rate);
  for (auto& node : spec->nodes) {
    if (node.kind == "recognise") node.params.assign("instructor", "0");
  }
  graphs::LearningSettings settings;
  auto descriptor = graphs::descriptor_of_graph(*spec);
  if (!descriptor) fail(descriptor.error(), EXIT_BAD_INPUT);
  settings.memory.descriptor = *descriptor;
  auto learning = graphs::LearningService::open(settings);
  if (!learning) fail(learning.error(), EXIT_FAILURE_GENERIC);
  graphs::SessionLog log(nullptr);
  const auto registry = graphs::make_tabletop_registry(**learning, log);
  auto graph = engine::build_graph(*spec, registry);
  if (!graph) fail(engine::to_string(graph.error()), EXIT_BAD_INPUT);
  engine::Engine engine(**graph, {a.threads});
  // Every frame's exact latency while the run is short enough to keep them (16 MB); past that the
  // engine's histogram (percentiles up to 12.5 % high).
  std::vector<std::int64_t> trace(a.frames <= EXACT_FRAMES_UP_TO ? a.frames : 0);
  {
    const StressLoad stress(a.stress);
    engine::RunOptions limits;
    limits.max_frames = a.frames;
    limits.latency_trace = trace;
    engine.run(limits);
  }
  const auto& stats = engine.stats();
  const auto& lat = stats.frame_latency;
  trace.resize(std::min<std::size_t>(trace.size(), stats.frames_done.load()));
  std::sort(trace.begin(), trace.end());
  const bool exact = !trace.empty() && trace.size() == stats.frames_done.load();
  const auto quantile = [&](double q) {
    return exact ? engine::exact_percentile(trace, q) : lat.percentile(q);
  };
  const double qs[] = {0.5, 0.9, 0.99, 0.999, 0.9999};
  const char* names[] = {"p50", "p90", "p99", "p99.9", "p99.99"};
  nlohmann::json latency = nlohmann::json::object();
  std::printf("orthoflow bench latency: graph '%s', %llu frames, %s, %d thread(s), stress %.2f\n",
              (*graph)->spec.name.c_str(), static_cast<unsigned long long>(lat.count()),
              stats.period_ns > 0
                  ? ("paced at " + std::to_string(1e9 / double(stats.period_ns)) + " Hz").c_str()
                  : "unpaced",
              a.threads, a.stress);
  std::printf("frame-to-labels latency (ms, %s):", exact ? "exact" : "histogram, 12.5 %% buckets");
  evaluation::Series curve{"frame latency", {}, {}, {}, true};
  for (std::size_t k = 0; k < 5; ++k) {
    const double ms = double(quantile(qs[k])) / 1e6;
    latency[names[k]] = ms;
    std::printf(" %s %.3f", names[k], ms);
    curve.x.push_back(double(k));
    curve.y.push_back(ms);
  }
  const double max_ms = double(lat.max()) / 1e6;
  latency["max"] = max_ms;
  curve.x.push_back(5.0);
  curve.y.push_back(max_ms);
  std::printf(" max %.3f\n", max_ms);
  std::printf("deadline misses: %llu of %llu frames (period %s)\n",
              static_cast<unsigned long long>(stats.deadline_misses.load()),
              static_cast<unsigned long long>(stats.frames_done.load()),
              stats.period_ns > 0 ? (std::to_string(double(stats.period_ns) / 1e6) + " ms").c_str()
                                  : "none: unpaced");
  const nlohmann::json machine = machine_json(a);
  std::printf("machine: %s, %u cores, %s %s, SIMD %s\ncompiler: %s; flags: %s\n",
              machine["cpu"].get<std::string>().c_str(), machine["cores"].get<unsigned>(),
              machine["kernel"].get<std::string>().c_str(),
              machine["arch"].get<std::string>().c_str(), kernels::simd_arch_name(), __VERSION__,
              ORTHOFLOW_CXX_FLAGS);
  std::cout << engine::format_table(stats);
  if (!a.json.empty()) {
    const nlohmann::json out = {{"frames", lat.count()},
                                {"latency_ms", latency},
                                {"percentiles", exact ? "exact" : "histogram"},
                                {"deadline_misses", stats.deadline_misses.load()},
                                {"period_ns", stats.period_ns},
                                {"machine", machine},
                                {"telemetry", nlohmann::json::parse(engine::to_json(stats))}};
    if (auto written = core::write_whole_file(a.json, out.dump(2) + '\n'); !written)
      fail("cannot write " + written.error(), EXIT_FAILURE_GENERIC);
  }
  if (!a.plot.empty()) {
    evaluation::PlotSpec plot;
    plot.title = "frame-to-labels latency (x: p50, p90, p99, p99.9, p99.99, max)";
    plot.x_label = "percentile (0 = p50 ... 4 = p99.99, 5 = max)";
    plot.y_label = "ms";
    plot.y_min = 0.0;
    plot.series.push_back(curve);
    if (auto ok = evaluation::write_plot_png(plot, a.plot); !ok) {
      fail(ok.error().to_string(), EXIT_FAILURE_GENERIC);
    }
  }
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks for the user's own machine");
  bench->require_subcommand(1);
  auto a = std::make_shared<BenchArgs>();
  CLI::App* cmd = bench->add_subcommand(
      "latency",
      "Frame-to-labels latency of a graph on a source, optionally beside a CPU stress load");
  cmd->add_option("--graph", a->graph, "graph file (default: the embedded graphs/tabletop.yaml)");
  cmd->add_option("--source", a->source,
                  "synthetic:SEED, pcd:DIR, kinect[:SERIAL] (the camera over USB) or "
                  "kinect-sim[:SEED] (the simulated camera) (default: the graph's source)");
  cmd->add_option("--frames", a->frames, "frames to run (default 300)")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{100000000}));
  cmd->add_option("--rate", a->rate,
                  "source rate in Hz (each frame's deadline), or max (unpaced); default: the "
                  "graph's period")
      ->check(check_rate);
  cmd->add_option("--threads", a->threads, "engine threads (default 1)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--stress", a->stress,
                  "CPU stress beside the graph: one thread per core busy this share of the time "
                  "(0-1)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--json", a->json, "write the report as JSON to FILE");
  cmd->add_option("--plot", a->plot, "write a PNG of the latency percentiles to FILE");
  cmd->callback([a] { run_bench(*a); });
}

}  // namespace orthoflow::apps
