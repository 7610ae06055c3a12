#pragma once
/// @file
/// @brief LatencyHistogram: lock-free log-linear histogram of nanosecond durations (8 sub-buckets
/// per power of two, so a reported percentile is at most 12.5% above the true value; max is exact).
#include <array>
#include <atomic>
#include <cstdint>
#include <span>

namespace orthoflow::engine {

/// @brief Records durations from any thread with relaxed atomics; never allocates.
/// @note Percentiles read while writers run are a consistent-enough snapshot, not exact.
class LatencyHistogram {
 public:
  static constexpr std::size_t SUB_BUCKETS = 8;
  static constexpr std::size_t BUCKETS = 16 + (64 - 4) * SUB_BUCKETS;

  /// @brief Adds one sample (negative values count as 0). Lock-free, wait-free except max.
  void record(std::int64_t ns) noexcept;
  [[nodiscard]] std::uint64_t count() const noexcept {
    return count_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::int64_t max() const noexcept { return max_.load(std::memory_order_relaxed); }
  /// @brief Upper bound of the bucket holding quantile q in [0, 1] (clamped to max); 0 if empty.
  [[nodiscard]] std::int64_t percentile(double q) const noexcept;
  /// @brief Bucket of a value, exposed for tests. @pre ns >= 0.
  [[nodiscard]] static std::size_t bucket_of(std::uint64_t ns) noexcept;
  /// @brief Largest value that falls into bucket `b`.
  [[nodiscard]] static std::uint64_t bucket_upper(std::size_t b) noexcept;

 private:
  std::array<std::atomic<std::uint64_t>, BUCKETS> buckets_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::int64_t> max_{0};
};

/// @brief The exact nearest-rank quantile q in [0, 1] of @p sorted (ascending): the sample of rank
/// ceil(q n), at least 1; 0 if empty. For exact samples (RunOptions::latency_trace) where the
/// histogram's 12.5 % buckets are too coarse.
[[nodiscard]] std::int64_t exact_percentile(std::span<const std::int64_t> sorted,
                                            double q) noexcept;

}  // namespace orthoflow::engine
