#pragma once
/// @file
/// @brief Telemetry: per-node and per-graph counters and latency histograms, updated lock-free on
/// the frame path, printed as a table or exported as JSON after (or during) a run.
#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <span>
#include <string>

#include "engine/histogram.hpp"

namespace orthoflow::engine {

/// @brief One named counter a node reports about the device behind it (a camera's lost packets,
/// resyncs, reopens...): the device's own account beside the graph's counters. @p name is a string
/// with static storage.
struct DeviceCounter {
  const char* name = "";
  std::uint64_t value = 0;
};
/// @brief Most device counters one node reports.
inline constexpr std::size_t MAX_DEVICE_COUNTERS = 24;

/// @brief Counters of one node. All fields are atomics written with relaxed ordering.
struct NodeStats {
  std::string name;                         ///< set at start-up
  bool sink = false;                        ///< no outputs: frame age is recorded here
  LatencyHistogram service;                 ///< time inside process()
  LatencyHistogram age;                     ///< sinks: now - source stamp when the message arrives
  std::atomic<std::uint64_t> processed{0};  ///< messages handed to process()
  std::atomic<std::uint64_t> dropped{0};    ///< stale messages skipped by the latest-wins policy
  std::atomic<std::uint64_t> skipped{0};    ///< tombstones passed through without processing
  std::atomic<std::uint64_t> deadline_misses{0};  ///< process() took longer than the node deadline
  std::atomic<std::uint32_t> running{0};          ///< process() calls in progress right now
  std::atomic<std::uint32_t> max_running{0};      ///< most process() calls ever seen at once
  /// Reads the node's device counters into the span, returns how many (set at start-up for every
  /// node; empty in hand-made stats). Any thread, while the graph lives.
  std::function<std::size_t(std::span<DeviceCounter>)> device;
  /// What those counters are about (Node::counter_group(): "device", "plane"): the table's label
  /// and the JSON member they are under.
  const char* counter_group = "device";
};

/// @brief Whole-graph counters plus one NodeStats per node (stable addresses: a deque).
struct GraphStats {
  std::string name;
  std::int64_t period_ns = 0;
  std::deque<NodeStats> nodes;
  LatencyHistogram frame_latency;                 ///< source stamp -> frame fully processed
  std::atomic<std::uint64_t> frames_in{0};        ///< frames produced by the source
  std::atomic<std::uint64_t> frames_done{0};      ///< frames fully processed (tombstones included)
  std::atomic<std::uint64_t> source_drops{0};     ///< frames the source could not fill (pool)
  std::atomic<std::uint64_t> deadline_misses{0};  ///< frames whose latency exceeded the period
  std::atomic<std::int64_t> elapsed_ns{0};        ///< wall time of the last run

  /// @brief Sum of drops over the source and every node.
  [[nodiscard]] std::uint64_t total_drops() const noexcept;
};

/// @brief Human-readable table: one row per node and a graph row (latencies in microseconds).
[[nodiscard]] std::string format_table(const GraphStats& stats);
/// @brief The same numbers as a JSON document (latencies in nanoseconds).
[[nodiscard]] std::string to_json(const GraphStats& stats);

}  // namespace orthoflow::engine
