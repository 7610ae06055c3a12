#pragma once
/// @file
/// @brief What `graph check|dot|run` and `ipc config|doctor|run` share (apps/cmd_graph.cpp): one
/// registry of every node kind, one way to load and validate a graph file, one way to run it.
#include <cstdint>
#include <memory>
#include <string>

#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "engine/registry.hpp"

namespace orthoflow::apps {

/// @brief Every kind a graph file may name: generic, IPC and tabletop (an in-memory learner and a
/// session log that live as long as the process). Throws CLI::RuntimeError if the learner fails.
[[nodiscard]] engine::NodeRegistry make_graph_registry();

/// @brief Loads and validates `file` (every graph error, cycles included, as `file:line: error
/// [CODE]: ...` on stderr, then CLI::RuntimeError(EXIT_BAD_INPUT)).
[[nodiscard]] std::unique_ptr<engine::Graph> load_graph_or_throw(
    const std::string& file, const engine::NodeRegistry& registry, engine::BuildMode mode);

/// @brief engine.run(options) under a RoudiWatch when the graph's IPC nodes registered with RouDi:
/// a lost RouDi stops the run within ~100 ms (engine::ipc_roudi_lost() says so afterwards).
/// Shared by `graph run`, `ipc run` and `orthoflow run --publish-objects`.
engine::StopReason run_watching_roudi(engine::Engine& engine, const engine::RunOptions& options);

/// @brief "RouDi lost while <doing> (ROUDI_LOST: RouDi no longer answers on /tmp/roudi)".
[[nodiscard]] std::string roudi_lost_text(const std::string& doing);

/// @brief Settings of one graph run.
struct GraphRunArgs {
  std::string file;
  std::uint64_t frames = 0;  ///< stop after N frames (0 = until the source ends or a signal)
  int threads = 0;           ///< arena threads including the caller (0 = all cores)
  std::string json;          ///< telemetry JSON file ('-' = stdout, empty = none)
  std::string command = "graph run";  ///< names the command in messages
};

/// @brief Runs a graph file until its source ends, `frames` or SIGINT/SIGTERM, then prints the
/// telemetry table and one line of counters per IPC node. While it runs a RoudiWatch stops it
/// within ~100 ms of RouDi disappearing; then it names RouDi and what was not published on stderr
/// and throws CLI::RuntimeError(EXIT_ROUDI_LOST).
void run_graph_file(const GraphRunArgs& args);

}  // namespace orthoflow::apps
