#pragma once
// SIMD body of spin_images(): the neighbour test and |d|, d . n of a batch of points in the scalar
// rule's float operation order (-ffp-contract=off); each neighbour is then binned by the shared
// scalar rule, in point order.
#include "kernels/detail/spin_image_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Arch>
std::size_t SpinNeighboursKernel::operator()(Arch /*arch*/, const SpinSetup& s, const SpinKey& k,
                                             PointsView points, PointsView normals,
                                             double* acc) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = points.size();
  const batch kx(k.x), ky(k.y), kz(k.z), nx(k.nx), ny(k.ny), nz(k.nz), r2(s.radius2);
  std::size_t found = 0;
  std::size_t i = 0;
  alignas(64) float norm[LANES];
  alignas(64) float dot[LANES];
  alignas(64) float dist2[LANES];
  for (; i + LANES <= n; i += LANES) {
    const batch dx = batch::load_unaligned(points.x.data() + i) - kx;
    const batch dy = batch::load_unaligned(points.y.data() + i) - ky;
    const batch dz = batch::load_unaligned(points.z.data() + i) - kz;
    const batch d2 = dx * dx + dy * dy + dz * dz;
    if (!xsimd::any(d2 < r2)) continue;
    d2.store_aligned(dist2);
    xsimd::sqrt(d2).store_aligned(norm);
    (dx * nx + dy * ny + dz * nz).store_aligned(dot);
    for (std::size_t l = 0; l < LANES; ++l) {
      if (!(dist2[l] < s.radius2)) continue;
      ++found;
      spin_bin(s, k, normals, i + l, norm[l], dot[l], acc);
    }
  }
  return found + spin_range(s, k, points, normals, i, n, acc);
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template std::size_t orthoflow::kernels::detail::SpinNeighboursKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, const orthoflow::kernels::detail::SpinSetup&,
    const orthoflow::kernels::detail::SpinKey&, orthoflow::kernels::PointsView,
    orthoflow::kernels::PointsView, double*) const noexcept;
#endif
