#pragma once
/// @file
/// @brief The table node's running account of its planes, for the telemetry (group "plane"): how
/// many frames had a plane, how many of those the table stage took another level for (the floor
/// below the table or an object's top: PlaneCheck::switched, the fallbacks), how many were doubtful
/// (fewer than DOUBTFUL_SHARE of the plane's tau inliers within 1 cm of it: a tilted plane), and
/// the worst and the last inlier share and residual; and the table verdicts: tables (accepted or
/// held), held, the refusals by reason, and the frames that knew no "up". Written from the frame
/// path with relaxed atomics; read from any thread.
#include <atomic>
#include <cstdint>
#include <span>

#include "engine/telemetry.hpp"
#include "kernels/table_verdict.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::graphs {

/// @brief A plane whose near share is below this is counted as doubtful. Right planes keep
/// 0.93-0.999 of their inliers within 1 cm on the 48 mOSD frames of ../shared/data (the farthest
/// table, test55, the least: Kinect noise grows with depth); a plane tilted by a degree over a 1 m
/// table keeps far fewer (docs/SEGMENTATION.md, "Plane quality in the product").
inline constexpr float DOUBTFUL_SHARE = 0.85F;

/// @brief Counters of the planes one table node found. Thread-safe, lock-free, allocation-free.
class PlaneQualityCounters {
 public:
  /// @brief Counts one frame's plane.
  void record(const kernels::PlaneCheck& check) noexcept;
  /// @brief Counts one frame's table verdict: @p verdict the frame's (HELD when the hysteresis kept
  /// the last table), @p own what its own plane got, @p gravity whether it knew where up is.
  void record_verdict(kernels::TableReason verdict, kernels::TableReason own,
                      bool gravity) noexcept;
  /// @brief Counts a sensor's "up" refused as too old.
  void record_stale_up() noexcept { up_stale_.fetch_add(1, std::memory_order_relaxed); }
  /// @brief Writes the counters (names with static storage) into @p out; @return how many.
  /// Shares are in parts per million, residuals in micrometres; the worst values are 0 before the
  /// first plane.
  std::size_t read(std::span<engine::DeviceCounter> out) const noexcept;

 private:
  std::atomic<std::uint64_t> frames_{0}, switched_{0}, doubtful_{0};
  std::atomic<std::uint64_t> last_share_ppm_{0}, last_rms_um_{0};
  std::atomic<std::uint64_t> min_share_ppm_{UINT64_MAX}, max_rms_um_{0};
  std::atomic<std::uint64_t> tables_{0}, held_{0}, not_level_{0}, out_of_range_{0}, too_small_{0};
  std::atomic<std::uint64_t> no_gravity_{0}, up_stale_{0};
};

}  // namespace orthoflow::graphs
