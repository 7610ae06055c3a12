#include "engine/histogram.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace orthoflow::engine {

// Values below 16 get one bucket each; above, exponent e = floor(log2 v) selects a group of 8
// buckets and the 3 bits below the leading one select the sub-bucket (HdrHistogram's layout).
std::size_t LatencyHistogram::bucket_of(std::uint64_t ns) noexcept {
  if (ns < 16) return static_cast<std::size_t>(ns);
  const auto e = static_cast<std::size_t>(std::bit_width(ns) - 1);
  const auto sub = static_cast<std::size_t>((ns >> (e - 3)) & (SUB_BUCKETS - 1));
  return 16 + (e - 4) * SUB_BUCKETS + sub;
}

std::uint64_t LatencyHistogram::bucket_upper(std::size_t b) noexcept {
  if (b < 16) return b;
  const std::size_t e = (b - 16) / SUB_BUCKETS + 4;
  const std::size_t sub = (b - 16) % SUB_BUCKETS;
  const std::uint64_t lower = (std::uint64_t{1} << e) | (std::uint64_t{sub} << (e - 3));
  return lower + (std::uint64_t{1} << (e - 3)) - 1;
}

void LatencyHistogram::record(std::int64_t ns) noexcept {
  const std::uint64_t value = ns < 0 ? 0 : static_cast<std::uint64_t>(ns);
  buckets_[bucket_of(value)].fetch_add(1, std::memory_order_relaxed);
  count_.fetch_add(1, std::memory_order_relaxed);
  std::int64_t seen = max_.load(std::memory_order_relaxed);
  const auto sample = static_cast<std::int64_t>(value);
  while (sample > seen && !max_.compare_exchange_weak(seen, sample, std::memory_order_relaxed)) {}
}

namespace {
// The nearest rank of quantile q (clamped to [0, 1]) among n > 0 samples: ceil(q n), at least 1.
std::uint64_t nearest_rank(double q, std::uint64_t n) noexcept {
  const double clamped = q < 0.0 ? 0.0 : (q > 1.0 ? 1.0 : q);
  const auto rank = static_cast<std::uint64_t>(std::ceil(clamped * static_cast<double>(n)));
  return std::clamp<std::uint64_t>(rank, 1, n);
}
}  // namespace

std::int64_t LatencyHistogram::percentile(double q) const noexcept {
  const std::uint64_t total = count();
  if (total == 0) return 0;
  const std::uint64_t rank = nearest_rank(q, total);
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < BUCKETS; ++b) {
    seen += buckets_[b].load(std::memory_order_relaxed);
    if (seen >= rank) {
      const auto upper = static_cast<std::int64_t>(bucket_upper(b));
      return upper < max() ? upper : max();
    }
  }
  return max();
}

std::int64_t exact_percentile(std::span<const std::int64_t> sorted, double q) noexcept {
  if (sorted.empty()) return 0;
  return sorted[nearest_rank(q, sorted.size()) - 1];
}

}  // namespace orthoflow::engine
