#pragma once
/// @file
/// @brief The table node's running account of its planes, for the telemetry (group "plane"): how
/// many frames had a plane, how many of those the table stage took another level for (the floor
/// below the table or an object's top: PlaneCheck::switched, the fallbacks), how many were doubtful
/// (fewer than DOUBTFUL_SHARE of the plane's tau inliers within 1 cm of it: a tilted plane), and
/// the worst and the last inlier share and residual. Written from the frame path with relaxed
/// atomics; read from any thread.
#include <atomic>
#include <cstdint>
#include <span>

#include "engine/telemetry.hpp"
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
  /// @brief Writes the counters (names with static storage) into @p out; @return how many.
  /// Shares are in parts per million, residuals in micrometres; the worst values are 0 before the
  /// first plane.
  std::size_t read(std::span<engine::DeviceCounter> out) const noexcept;

 private:
  std::atomic<std::uint64_t> frames_{0}, switched_{0}, doubtful_{0};
  std::atomic<std::uint64_t> last_share_ppm_{0}, last_rms_um_{0};
  std::atomic<std::uint64_t> min_share_ppm_{UINT64_MAX}, max_rms_um_{0};
};

}  // namespace orthoflow::graphs
