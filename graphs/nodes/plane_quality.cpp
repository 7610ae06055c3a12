#include "graphs/nodes/plane_quality.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace orthoflow::graphs {

namespace {

std::uint64_t scaled(float value, double scale) noexcept {
  if (!std::isfinite(value) || value <= 0.0F) return 0;
  return static_cast<std::uint64_t>(std::llround(static_cast<double>(value) * scale));
}

void lower_to(std::atomic<std::uint64_t>& a, std::uint64_t v) noexcept {
  std::uint64_t seen = a.load(std::memory_order_relaxed);
  while (v < seen && !a.compare_exchange_weak(seen, v, std::memory_order_relaxed)) {}
}

void raise_to(std::atomic<std::uint64_t>& a, std::uint64_t v) noexcept {
  std::uint64_t seen = a.load(std::memory_order_relaxed);
  while (v > seen && !a.compare_exchange_weak(seen, v, std::memory_order_relaxed)) {}
}

}  // namespace

void PlaneQualityCounters::record(const kernels::PlaneCheck& check) noexcept {
  const std::uint64_t share = scaled(check.near_share, 1e6), rms = scaled(check.rms_m, 1e6);
  frames_.fetch_add(1, std::memory_order_relaxed);
  if (check.switched) switched_.fetch_add(1, std::memory_order_relaxed);
  if (!(check.near_share >= DOUBTFUL_SHARE)) doubtful_.fetch_add(1, std::memory_order_relaxed);
  last_share_ppm_.store(share, std::memory_order_relaxed);
  last_rms_um_.store(rms, std::memory_order_relaxed);
  lower_to(min_share_ppm_, share);
  raise_to(max_rms_um_, rms);
}

void PlaneQualityCounters::record_verdict(kernels::TableReason verdict, kernels::TableReason own,
                                          bool gravity) noexcept {
  using R = kernels::TableReason;
  constexpr auto relaxed = std::memory_order_relaxed;
  if (!gravity) no_gravity_.fetch_add(1, relaxed);
  if (verdict == R::ACCEPTED || verdict == R::HELD) tables_.fetch_add(1, relaxed);
  if (verdict == R::HELD) held_.fetch_add(1, relaxed);
  if (own == R::NOT_LEVEL) not_level_.fetch_add(1, relaxed);
  if (own == R::OUT_OF_RANGE) out_of_range_.fetch_add(1, relaxed);
  if (own == R::TOO_SMALL) too_small_.fetch_add(1, relaxed);
}

std::size_t PlaneQualityCounters::read(std::span<engine::DeviceCounter> out) const noexcept {
  const std::uint64_t min_share = min_share_ppm_.load(std::memory_order_relaxed);
  constexpr auto relaxed = std::memory_order_relaxed;
  const std::array<engine::DeviceCounter, 14> all{{
      {"frames", frames_.load(std::memory_order_relaxed)},
      {"switched", switched_.load(std::memory_order_relaxed)},
      {"doubtful", doubtful_.load(std::memory_order_relaxed)},
      {"near_share_min_ppm", min_share == UINT64_MAX ? 0 : min_share},
      {"near_share_last_ppm", last_share_ppm_.load(std::memory_order_relaxed)},
      {"rms_max_um", max_rms_um_.load(std::memory_order_relaxed)},
      {"rms_last_um", last_rms_um_.load(std::memory_order_relaxed)},
      {"tables", tables_.load(relaxed)},
      {"held", held_.load(relaxed)},
      {"refused_not_level", not_level_.load(relaxed)},
      {"refused_out_of_range", out_of_range_.load(relaxed)},
      {"refused_too_small", too_small_.load(relaxed)},
      {"no_gravity", no_gravity_.load(relaxed)},
      {"up_stale", up_stale_.load(relaxed)},
  }};
  const std::size_t k = std::min(out.size(), all.size());
  std::copy_n(all.begin(), k, out.begin());
  return k;
}

}  // namespace orthoflow::graphs
