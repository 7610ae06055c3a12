#include "kernels/cloud_stats.hpp"

#include <limits>

#include "kernels/detail/cloud_stats_kernel.hpp"

namespace orthoflow::kernels {

CloudStats cloud_stats_scalar(PointsView points) noexcept {
  const float inf = std::numeric_limits<float>::infinity();
  CloudStats stats{0, {inf, inf, inf}, {-inf, -inf, -inf}};
  detail::accumulate_scalar(points, 0, points.size(), stats);
  return stats;
}

CloudStats cloud_stats(PointsView points) noexcept {
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::CloudStatsKernel{});
  return dispatched(points);
}

}  // namespace orthoflow::kernels
