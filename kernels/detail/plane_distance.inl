#pragma once
// SIMD bodies of count_plane_inliers() and plane_signed_distance().
#include "kernels/detail/plane_distance_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Arch>
std::size_t PlaneInlierKernel::operator()(Arch /*arch*/, PointsView pts, const Plane& plane,
                                          float tau) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = pts.size();
  const batch a(plane.normal[0]), b(plane.normal[1]), c(plane.normal[2]), d(plane.d), t(tau);
  // Two independent accumulators (even / odd batch): one add chain per batch would bound the loop
  // by the add latency, not by the loads. Flushed before any lane can reach 2^24 (exact in float).
  batch count0(0.0F), count1(0.0F);
  const batch one(1.0F), zero(0.0F);
  std::size_t total = 0;
  std::size_t since_flush = 0;
  std::size_t i = 0;
  auto inliers = [&](std::size_t k) {
    const batch dist = a * batch::load_unaligned(pts.x.data() + k) +
                       b * batch::load_unaligned(pts.y.data() + k) +
                       c * batch::load_unaligned(pts.z.data() + k) + d;
    return xsimd::select(xsimd::abs(dist) <= t, one, zero);
  };
  for (; i + 2 * LANES <= n; i += 2 * LANES) {
    count0 = count0 + inliers(i);
    count1 = count1 + inliers(i + LANES);
    if (++since_flush == (1U << 20)) {
      total += static_cast<std::size_t>(xsimd::hadd(count0 + count1));
      count0 = count1 = zero;
      since_flush = 0;
    }
  }
  if (i + LANES <= n) {
    count0 = count0 + inliers(i);
    i += LANES;
  }
  total += static_cast<std::size_t>(xsimd::hadd(count0 + count1));
  return total + count_inliers_range(pts, plane, tau, i, n);
}

template <class Arch>
std::size_t PlaneDistanceKernel::operator()(Arch /*arch*/, PointsView pts, const Plane& plane,
                                            std::span<float> out) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = pts.size();
  const batch a(plane.normal[0]), b(plane.normal[1]), c(plane.normal[2]), d(plane.d);
  std::size_t i = 0;
  for (; i + LANES <= n; i += LANES) {
    const batch dist = a * batch::load_unaligned(pts.x.data() + i) +
                       b * batch::load_unaligned(pts.y.data() + i) +
                       c * batch::load_unaligned(pts.z.data() + i) + d;
    dist.store_unaligned(out.data() + i);
  }
  for (; i < n; ++i) { out[i] = plane_distance(plane, pts.x[i], pts.y[i], pts.z[i]); }
  return n;
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template std::size_t orthoflow::kernels::detail::PlaneInlierKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView, const orthoflow::kernels::Plane&,
    float) const noexcept;
template std::size_t orthoflow::kernels::detail::PlaneDistanceKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView, const orthoflow::kernels::Plane&,
    std::span<float>) const noexcept;
#endif
