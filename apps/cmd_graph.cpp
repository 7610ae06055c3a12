// `orthoflow graph check|dot|run FILE`: validate, draw and run a dataflow graph file.
#include <atomic>
#include <csignal>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.hpp"
#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "engine/registry.hpp"
#include "graphs/tabletop.hpp"

namespace orthoflow::apps {

namespace {

// Written only by the signal handler, read by the engine's source: a lock-free atomic is the one
// thing that is async-signal-safe here.
std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void on_stop_signal(int /*signal*/) {
  g_stop_requested.store(true, std::memory_order_relaxed);
}

// Every kind a graph file may name: generic, IPC and tabletop. The tabletop kinds recognise and
// session_log bind to a learner and a log that live as long as the process (in memory: `graph run`
// is for running and timing graphs; `orthoflow run` is the command with a durable memory and a
// summary).
engine::NodeRegistry make_registry() {
  static auto learning = graphs::LearningService::open({});
  static graphs::SessionLog log;
  if (!learning) {
    std::cerr << learning.error() << "\n";
    throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
  }
  return graphs::make_tabletop_registry(**learning, log);
}

// `graph check` and `graph dot` build with BuildMode::CHECK: every error a file can hold is
// reported with the same message and exit code as `graph run`, but no node connects (no RouDi
// needed).
std::unique_ptr<engine::Graph> load_or_throw(const std::string& file,
                                             const engine::NodeRegistry& registry,
                                             engine::BuildMode mode) {
  auto spec_result = engine::load_graph_file(file);
  if (!spec_result) {
    std::cerr << engine::to_string(spec_result.error()) << "\n";
    throw CLI::RuntimeError(EXIT_BAD_INPUT);
  }
  auto graph_result = engine::build_graph(*spec_result, registry, mode);
  if (!graph_result) {
    std::cerr << engine::to_string(graph_result.error()) << "\n";
    throw CLI::RuntimeError(EXIT_BAD_INPUT);
  }
  return std::move(*graph_result);
}

struct RunArgs {
  std::string file;
  std::uint64_t frames = 0;
  int threads = 0;
  std::string json;
};

void run_graph(const RunArgs& args) {
  const auto registry = make_registry();
  auto graph = load_or_throw(args.file, registry, engine::BuildMode::RUN);
  g_stop_requested.store(false);
  auto previous_int = std::signal(SIGINT, on_stop_signal);
  auto previous_term = std::signal(SIGTERM, on_stop_signal);
  engine::StopReason reason = engine::StopReason::SOURCE_END;
  std::string table;
  std::string json;
  {
    engine::Engine runner(*graph, {args.threads});
    reason = runner.run({args.frames, &g_stop_requested});
    table = engine::format_table(runner.stats());
    json = engine::to_json(runner.stats());
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  const char* why = reason == engine::StopReason::STOP_REQUESTED ? "stopped by signal"
                    : reason == engine::StopReason::FRAME_LIMIT  ? "frame limit reached"
                                                                 : "source ended";
  std::cout << table << "(" << why << ", all in-flight frames drained)\n";
  if (args.json == "-") {
    std::cout << json << "\n";
  } else if (!args.json.empty()) {
    std::ofstream out(args.json);
    if (!(out << json << "\n")) {
      std::cerr << "graph run: cannot write telemetry JSON to '" << args.json << "'\n";
      throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
    }
  }
}

}  // namespace

void add_graph_command(CLI::App& app) {
  auto* graph = app.add_subcommand("graph", "Validate, draw or run a dataflow graph file (YAML)");
  graph->require_subcommand(1);

  auto check_file = std::make_shared<std::string>();
  auto* check = graph->add_subcommand(
      "check", "Validate a graph file (no RouDi needed); errors name file and line");
  check->add_option("FILE", *check_file, "graph file")->required();
  check->callback([check_file] {
    const auto registry = make_registry();
    auto built = load_or_throw(*check_file, registry, engine::BuildMode::CHECK);
    std::cout << *check_file << ": ok (" << built->nodes.size() << " nodes, " << built->edges.size()
              << " edges, " << built->max_in_flight << " frames in flight)\n";
  });

  auto dot_file = std::make_shared<std::string>();
  auto* dot = graph->add_subcommand("dot", "Print the graph in Graphviz dot format");
  dot->add_option("FILE", *dot_file, "graph file")->required();
  dot->callback([dot_file] {
    const auto registry = make_registry();
    std::cout << engine::to_dot(*load_or_throw(*dot_file, registry, engine::BuildMode::CHECK));
  });

  auto args = std::make_shared<RunArgs>();
  auto* run =
      graph->add_subcommand("run", "Run a graph; SIGINT/SIGTERM drain and stop; prints telemetry");
  run->add_option("FILE", args->file, "graph file")->required();
  run->add_option("--frames", args->frames,
                  "stop after N frames (0 = until the source ends or a signal)");
  run->add_option("--threads", args->threads, "arena threads including this one (0 = all cores)")
      ->check(CLI::Range(0, 1024));
  run->add_option("--json", args->json, "also write telemetry JSON to this file ('-' = stdout)");
  run->callback([args] { run_graph(*args); });
}

}  // namespace orthoflow::apps
