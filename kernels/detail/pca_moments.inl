#pragma once
// SIMD body of pca_moments(): floats widened to double lanes, non-finite lanes masked to zero, nine
// per-lane sums reduced once at the end.
#include "kernels/detail/pca_moments_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Arch>
PcaMoments PcaMomentsKernel::operator()(Arch /*arch*/, PointsView points,
                                        PcaMoments m) const noexcept {
  using batch = xsimd::batch<double, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = points.size();
  const batch zero(0.0), ox(m.origin[0]), oy(m.origin[1]), oz(m.origin[2]);
  batch s[3] = {zero, zero, zero};
  batch q[6] = {zero, zero, zero, zero, zero, zero};
  batch count = zero;
  std::size_t i = 0;
  for (; i + LANES <= n; i += LANES) {
    const batch x = batch::load_unaligned(points.x.data() + i);  // float -> double on load
    const batch y = batch::load_unaligned(points.y.data() + i);
    const batch z = batch::load_unaligned(points.z.data() + i);
    const auto ok = ((x - x) == zero) && ((y - y) == zero) && ((z - z) == zero);
    const batch dx = xsimd::select(ok, x - ox, zero);
    const batch dy = xsimd::select(ok, y - oy, zero);
    const batch dz = xsimd::select(ok, z - oz, zero);
    s[0] += dx;
    s[1] += dy;
    s[2] += dz;
    q[0] += dx * dx;
    q[1] += dx * dy;
    q[2] += dx * dz;
    q[3] += dy * dy;
    q[4] += dy * dz;
    q[5] += dz * dz;
    count += xsimd::select(ok, batch(1.0), zero);
  }
  for (std::size_t a = 0; a < 3; ++a) { m.sum[a] += xsimd::hadd(s[a]); }
  for (std::size_t a = 0; a < 6; ++a) { m.sq[a] += xsimd::hadd(q[a]); }
  m.count += static_cast<std::size_t>(xsimd::hadd(count));
  add_moments_scalar(points, i, n, m);
  return m;
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template orthoflow::kernels::PcaMoments
orthoflow::kernels::detail::PcaMomentsKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView, orthoflow::kernels::PcaMoments) const noexcept;
#endif
