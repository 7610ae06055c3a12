#pragma once
// Declaration of the cloud_stats() SIMD functor; the body is in cloud_stats.inl (one TU per arch).
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "kernels/cloud_stats.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

struct CloudStatsKernel {
  template <class Arch>
  CloudStats operator()(Arch arch, PointsView points) const noexcept;
};

/// Adds points [begin, end) to @p stats with the scalar rule (shared by the twin and the SIMD
/// tail).
inline void accumulate_scalar(PointsView points, std::size_t begin, std::size_t end,
                              CloudStats& stats) noexcept {
  for (std::size_t i = begin; i < end; ++i) {
    const float x = points.x[i];
    const float y = points.y[i];
    const float z = points.z[i];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) { continue; }
    ++stats.finite;
    stats.min = {std::min(stats.min[0], x), std::min(stats.min[1], y), std::min(stats.min[2], z)};
    stats.max = {std::max(stats.max[0], x), std::max(stats.max[1], y), std::max(stats.max[2], z)};
  }
}

}  // namespace orthoflow::kernels::detail
