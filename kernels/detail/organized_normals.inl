#pragma once
// SIMD body of organized_normals(): one row at a time, lanes across columns; the depth test and the
// cross product of normals_range() lane-wise (NaN neighbours fail the depth test, so they need no
// branch), the normalisation per lane through the scalar finish_normal() (xsimd's NEON float sqrt
// and division are estimates), so every variant equals the scalar twin bit for bit.
#include "kernels/detail/organized_normals_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Arch>
std::size_t OrganizedNormalsRowKernel::operator()(Arch /*arch*/, CloudView cloud,
                                                  const NormalParams& prm, std::size_t r,
                                                  std::size_t begin, std::size_t end,
                                                  PointsSpan out) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const PointsView p = cloud.points;
  const std::size_t w = cloud.width, s = prm.offset;
  std::size_t written = 0;
  std::size_t c = begin;
  auto load = [](std::span<const float> a, std::size_t i) { return batch::load_unaligned(&a[i]); };
  for (; c + LANES <= end; c += LANES) {
    const std::size_t i = r * w + c;
    const std::size_t up = i - s * w, down = i + s * w, left = i - s, right = i + s;
    const batch z = load(p.z, i);
    const batch limit = batch(prm.depth_change) * z;
    const batch zu = load(p.z, up), zd = load(p.z, down), zl = load(p.z, left),
                zr = load(p.z, right);
    const auto ok = (xsimd::abs(zu - z) <= limit) && (xsimd::abs(zd - z) <= limit) &&
                    (xsimd::abs(zl - z) <= limit) && (xsimd::abs(zr - z) <= limit);
    const batch vx = load(p.x, down) - load(p.x, up), vy = load(p.y, down) - load(p.y, up),
                vz = zd - zu;
    const batch hx = load(p.x, right) - load(p.x, left), hy = load(p.y, right) - load(p.y, left),
                hz = zr - zl;
    // The cross product lane-wise (exact IEEE operations); the rest per lane, scalar.
    alignas(64) float nx[LANES], ny[LANES], nz[LANES], flags[LANES];
    (vy * hz - vz * hy).store_aligned(nx);
    (vz * hx - vx * hz).store_aligned(ny);
    (vx * hy - vy * hx).store_aligned(nz);
    xsimd::select(ok, batch(1.0F), batch(0.0F)).store_aligned(flags);
    for (std::size_t l = 0; l < LANES; ++l) {
      if (flags[l] != 0.0F) {
        written += finish_normal(p, i + l, nx[l], ny[l], nz[l], out) ? 1U : 0U;
      } else {
        set_nan(out, i + l);
      }
    }
  }
  return written + normals_range(cloud, prm, r, c, end, out);
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template std::size_t
orthoflow::kernels::detail::OrganizedNormalsRowKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::CloudView, const orthoflow::kernels::NormalParams&,
    std::size_t, std::size_t, std::size_t, orthoflow::kernels::PointsSpan) const noexcept;
#endif
