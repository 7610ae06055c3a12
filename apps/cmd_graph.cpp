// `orthoflow graph check|dot|run FILE`: validate, draw and run a dataflow graph file; the loading
// and running shared with `orthoflow ipc` (apps/graph_run.hpp).
#include <atomic>
#include <csignal>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "apps/commands.hpp"
#include "apps/graph_run.hpp"
#include "core/file_output.hpp"
#include "engine/engine.hpp"
#include "engine/ipc_nodes.hpp"
#include "engine/roudi_watch.hpp"
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

// Counters of every IPC node after a run; a publisher's `unpublished` are the samples it did not
// send because RouDi was gone (so the summary never claims them).
void print_ipc_counters(const engine::Graph& graph, const engine::Engine& runner) {
  for (const auto& node : graph.spec.nodes) {
    const auto* ipc = dynamic_cast<const engine::IpcNode*>(runner.node(node.name));
    if (ipc == nullptr) continue;
    const auto& c = ipc->ipc_counters();
    std::cout << "ipc " << node.name << " " << ipc->topic() << " samples " << c.samples.load()
              << " dropped " << c.dropped.load() << " rejected " << c.rejected.load()
              << " loan_failures " << c.loan_failures.load() << " unpublished "
              << c.unpublished.load() << "\n";
  }
}

std::uint64_t unpublished_of(const engine::Graph& graph, const engine::Engine& runner) {
  std::uint64_t total = 0;
  for (const auto& node : graph.spec.nodes) {
    const auto* ipc = dynamic_cast<const engine::IpcNode*>(runner.node(node.name));
    if (ipc != nullptr) total += ipc->ipc_counters().unpublished.load();
  }
  return total;
}

void write_json(const GraphRunArgs& args, const std::string& json) {
  if (args.json == "-") {
    std::cout << json << "\n";
  } else if (!args.json.empty()) {
    if (auto written = core::write_whole_file(args.json, json + "\n"); !written) {
      std::cerr << args.command << ": cannot write telemetry JSON: " << written.error() << "\n";
      throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
    }
  }
}

}  // namespace

// The tabletop kinds recognise and session_log bind to a learner and a log that live as long as the
// process (in memory: `graph run` is for running and timing graphs; `orthoflow run` is the command
// with a durable memory and a summary).
engine::NodeRegistry make_graph_registry() {
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
std::unique_ptr<engine::Graph> load_graph_or_throw(const std::string& file,
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

engine::StopReason run_watching_roudi(engine::Engine& engine, const engine::RunOptions& options) {
  // Only a graph whose IPC nodes registered with RouDi is watched; the watch ends the run within
  // ~100 ms of a loss, also when no IPC node is busy.
  std::optional<engine::RoudiWatch> watch;
  if (engine::ipc_runtime_ready()) watch.emplace([&engine] { engine.request_stop(); });
  return engine.run(options);
}

std::string roudi_lost_text(const std::string& doing) {
  return "RouDi lost while " + doing + " (ROUDI_LOST: RouDi no longer answers on " +
         std::string(engine::ROUDI_SOCKET_PATH) + ")";
}

void run_graph_file(const GraphRunArgs& args) {
  const auto registry = make_graph_registry();
  auto graph = load_graph_or_throw(args.file, registry, engine::BuildMode::RUN);
  g_stop_requested.store(false);
  auto previous_int = std::signal(SIGINT, on_stop_signal);
  auto previous_term = std::signal(SIGTERM, on_stop_signal);
  engine::StopReason reason = engine::StopReason::SOURCE_END;
  std::string json;
  std::uint64_t unpublished = 0;
  {
    engine::Engine runner(*graph, {args.threads});
    reason = run_watching_roudi(runner, {args.frames, &g_stop_requested});
    std::cout << engine::format_table(runner.stats());
    json = engine::to_json(runner.stats());
    print_ipc_counters(*graph, runner);
    unpublished = unpublished_of(*graph, runner);
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  const bool lost = engine::ipc_roudi_lost();
  const char* why = lost                                           ? "RouDi lost"
                    : reason == engine::StopReason::STOP_REQUESTED ? "stopped by signal"
                    : reason == engine::StopReason::FRAME_LIMIT    ? "frame limit reached"
                                                                   : "source ended";
  std::cout << "(" << why << ", all in-flight frames drained)\n";
  write_json(args, json);
  std::cout.flush();
  if (lost) {
    std::cerr << args.command << ": " << roudi_lost_text("running " + args.file) << "; "
              << unpublished << " sample(s) not published; the IPC counters above count only what "
              << "reached shared memory before the loss\n";
    throw CLI::RuntimeError(EXIT_ROUDI_LOST);
  }
}

void add_graph_command(CLI::App& app) {
  auto* graph = app.add_subcommand("graph", "Validate, draw or run a dataflow graph file (YAML)");
  graph->require_subcommand(1);

  auto check_file = std::make_shared<std::string>();
  auto* check = graph->add_subcommand(
      "check", "Validate a graph file (no RouDi needed); errors name file and line");
  check->add_option("FILE", *check_file, "graph file")->required();
  check->callback([check_file] {
    const auto registry = make_graph_registry();
    auto built = load_graph_or_throw(*check_file, registry, engine::BuildMode::CHECK);
    std::cout << *check_file << ": ok (" << built->nodes.size() << " nodes, " << built->edges.size()
              << " edges, " << built->max_in_flight << " frames in flight)\n";
  });

  auto dot_file = std::make_shared<std::string>();
  auto* dot = graph->add_subcommand("dot", "Print the graph in Graphviz dot format");
  dot->add_option("FILE", *dot_file, "graph file")->required();
  dot->callback([dot_file] {
    const auto registry = make_graph_registry();
    std::cout << engine::to_dot(
        *load_graph_or_throw(*dot_file, registry, engine::BuildMode::CHECK));
  });

  auto args = std::make_shared<GraphRunArgs>();
  auto* run =
      graph->add_subcommand("run",
                            "Run a graph; SIGINT/SIGTERM drain and stop; prints telemetry; exit 22 "
                            "if RouDi is lost under its IPC nodes");
  run->add_option("FILE", args->file, "graph file")->required();
  run->add_option("--frames", args->frames,
                  "stop after N frames (0 = until the source ends or a signal)");
  run->add_option("--threads", args->threads, "arena threads including this one (0 = all cores)")
      ->check(CLI::Range(0, 1024));
  run->add_option("--json", args->json, "also write telemetry JSON to this file ('-' = stdout)");
  run->callback([args] { run_graph_file(*args); });
}

}  // namespace orthoflow::apps
