#pragma once
/// @file
/// @brief The objects node's running account of its work budget (kernels::ObjectBudget), for the
/// telemetry (group "budget"): the frames it segmented, how many it clustered at a coarser stride,
/// how many skipped the crowded refinements, how many dropped their farthest candidates (and how
/// many candidates that was), and the most prism pixels one frame held. Written from the frame path
/// with relaxed atomics; read from any thread.
#include <atomic>
#include <cstdint>
#include <span>

#include "engine/telemetry.hpp"
#include "graphs/frame/frame_block.hpp"

namespace orthoflow::graphs {

/// @brief Counters of one objects node's budget. Thread-safe, lock-free, allocation-free.
class BudgetCounters {
 public:
  /// @brief Counts one frame (one with a table, or not: it counts only what the stage did).
  void record(const FrameState& s) noexcept {
    if (!s.table_found) return;
    constexpr auto r = std::memory_order_relaxed;
    frames_.fetch_add(1, r);
    if (s.stride > 1) strided_.fetch_add(1, r);
    if (!s.refined) unrefined_.fetch_add(1, r);
    if (s.rejected_capacity > 0) {
      far_dropped_frames_.fetch_add(1, r);
      far_dropped_.fetch_add(s.rejected_capacity, r);
    }
    std::uint64_t seen = prism_max_.load(r);
    while (s.prism_points > seen && !prism_max_.compare_exchange_weak(seen, s.prism_points, r)) {}
  }
  /// @brief Writes the counters (names with static storage) into @p out; @return how many.
  std::size_t read(std::span<engine::DeviceCounter> out) const noexcept {
    constexpr auto r = std::memory_order_relaxed;
    const engine::DeviceCounter all[] = {
        {"frames", frames_.load(r)},           {"strided", strided_.load(r)},
        {"unrefined", unrefined_.load(r)},     {"far_dropped_frames", far_dropped_frames_.load(r)},
        {"far_dropped", far_dropped_.load(r)}, {"prism_points_max", prism_max_.load(r)}};
    std::size_t n = 0;
    for (; n < std::size(all) && n < out.size(); ++n) out[n] = all[n];
    return n;
  }

 private:
  std::atomic<std::uint64_t> frames_{0}, strided_{0}, unrefined_{0};
  std::atomic<std::uint64_t> far_dropped_frames_{0}, far_dropped_{0}, prism_max_{0};
};

}  // namespace orthoflow::graphs
