#pragma once
// SIMD body of cloud_stats(): one pass, lane-wise finite mask, min/max and count.
#include <limits>

#include "kernels/detail/cloud_stats_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Arch>
CloudStats CloudStatsKernel::operator()(Arch /*arch*/, PointsView points) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = points.size();
  const float inf = std::numeric_limits<float>::infinity();
  batch lo_x(inf), lo_y(inf), lo_z(inf), hi_x(-inf), hi_y(-inf), hi_z(-inf);
  batch count(0.0F);  // exact up to 2^24 per lane; flushed to an integer counter below
  std::size_t finite = 0;
  std::size_t i = 0;
  std::size_t since_flush = 0;
  for (; i + LANES <= n; i += LANES) {
    const batch x = batch::load_unaligned(points.x.data() + i);
    const batch y = batch::load_unaligned(points.y.data() + i);
    const batch z = batch::load_unaligned(points.z.data() + i);
    // x - x is 0 for finite values and NaN for NaN and +-Inf.
    const auto ok =
        ((x - x) == batch(0.0F)) && ((y - y) == batch(0.0F)) && ((z - z) == batch(0.0F));
    lo_x = xsimd::select(ok, xsimd::min(lo_x, x), lo_x);
    lo_y = xsimd::select(ok, xsimd::min(lo_y, y), lo_y);
    lo_z = xsimd::select(ok, xsimd::min(lo_z, z), lo_z);
    hi_x = xsimd::select(ok, xsimd::max(hi_x, x), hi_x);
    hi_y = xsimd::select(ok, xsimd::max(hi_y, y), hi_y);
    hi_z = xsimd::select(ok, xsimd::max(hi_z, z), hi_z);
    count = count + xsimd::select(ok, batch(1.0F), batch(0.0F));
    if (++since_flush == (1U << 20)) {
      finite += static_cast<std::size_t>(xsimd::hadd(count));
      count = batch(0.0F);
      since_flush = 0;
    }
  }
  finite += static_cast<std::size_t>(xsimd::hadd(count));
  CloudStats stats;
  alignas(64) float buf[6][LANES];
  lo_x.store_unaligned(buf[0]);
  lo_y.store_unaligned(buf[1]);
  lo_z.store_unaligned(buf[2]);
  hi_x.store_unaligned(buf[3]);
  hi_y.store_unaligned(buf[4]);
  hi_z.store_unaligned(buf[5]);
  stats.min = {inf, inf, inf};
  stats.max = {-inf, -inf, -inf};
  for (std::size_t l = 0; l < LANES; ++l) {
    for (std::size_t a = 0; a < 3; ++a) {
      stats.min[a] = std::min(stats.min[a], buf[a][l]);
      stats.max[a] = std::max(stats.max[a], buf[3 + a][l]);
    }
  }
  stats.finite = finite;
  // Scalar tail: the same rule as cloud_stats_scalar().
  accumulate_scalar(points, i, n, stats);
  return stats;
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template orthoflow::kernels::CloudStats orthoflow::kernels::detail::CloudStatsKernel::operator()<
    OF_SIMD_ARCH>(OF_SIMD_ARCH, orthoflow::kernels::PointsView) const noexcept;
#endif
