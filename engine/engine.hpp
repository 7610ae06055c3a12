#pragma once
/// @file
/// @brief Engine: runs a validated Graph on a oneTBB flow graph inside one task_arena it owns.
/// Admission (max_in_flight tokens, <= pool blocks) -> source -> nodes; stateless nodes run with
/// unlimited concurrency, stateful ones serially; `ordered` nodes sit behind a sequencer keyed by
/// frame id; `latest` nodes skip stale frames. See engine/README.md for the model.
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "engine/graph.hpp"
#include "engine/telemetry.hpp"

namespace orthoflow::engine {

/// @brief Engine start-up settings.
struct EngineConfig {
  int threads = 0;  ///< arena concurrency including the calling thread; 0 = all cores; 1 works
};

/// @brief Per-run settings.
struct RunOptions {
  std::uint64_t max_frames = 0;  ///< stop the source after this many frames (0 = no limit)
  const std::atomic<bool>* stop = nullptr;  ///< external stop flag (e.g. set by a signal handler)
  /// Optional: every frame's exact latency (source stamp -> frame fully processed, ns), the k-th
  /// frame to finish at index k, while k < size; the histogram's buckets are 12.5 % wide, this is
  /// for comparisons finer than that. Caller-owned; the frame path writes one slot and never
  /// allocates. After run(), min(stats().frames_done, size) slots are written.
  std::span<std::int64_t> latency_trace{};
};

/// @brief Why run() returned. In every case all in-flight frames were drained first.
enum class StopReason { SOURCE_END, FRAME_LIMIT, STOP_REQUESTED };

/// @brief Owns the TBB flow graph and arena for one Graph.
/// @pre `graph` outlives the engine and was built with BuildMode::RUN (OF_ENFORCE: a CHECK graph's
/// nodes are connected to nothing). run() is called at most once (a finished flow graph cannot
/// restart its source); request_stop() may be called from any thread, including signal-driven ones
/// through RunOptions::stop.
class Engine {
 public:
  Engine(Graph& graph, const EngineConfig& config);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// @brief Runs until the source ends, max_frames were produced or a stop is requested, then
  /// drains in-flight frames (at most max_in_flight + 1) and returns. Blocks the caller, which
  /// joins the arena as one of its threads.
  StopReason run(const RunOptions& options);
  /// @brief Asks the source to stop; run() returns after draining. Thread-safe, lock-free.
  void request_stop() noexcept;
  /// @brief Live telemetry (safe to read while running; exact after run() returns).
  [[nodiscard]] const GraphStats& stats() const noexcept;
  /// @brief The node instance named `name`, or nullptr.
  [[nodiscard]] Node* node(std::string_view name) const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace orthoflow::engine
