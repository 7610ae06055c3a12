#pragma once
// SIMD body of organized_normals(): one row at a time, lanes across columns; the rule of
// normals_range() lane-wise (NaN neighbours fail the depth test, so they need no branch).
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
  const batch nan(std::numeric_limits<float>::quiet_NaN());
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
    batch nx = vy * hz - vz * hy, ny = vz * hx - vx * hz, nz = vx * hy - vy * hx;
    const batch len = xsimd::sqrt(nx * nx + ny * ny + nz * nz);
    const batch facing = nx * load(p.x, i) + ny * load(p.y, i) + nz * z;
    const batch scale = xsimd::select(facing > batch(0.0F), batch(-1.0F), batch(1.0F)) / len;
    nx = nx * scale, ny = ny * scale, nz = nz * scale;
    const auto good = ok && (len > batch(0.0F)) && xsimd::isfinite(nx) && xsimd::isfinite(ny) &&
                      xsimd::isfinite(nz);
    xsimd::select(good, nx, nan).store_unaligned(&out.x[i]);
    xsimd::select(good, ny, nan).store_unaligned(&out.y[i]);
    xsimd::select(good, nz, nan).store_unaligned(&out.z[i]);
    alignas(64) float flags[LANES];
    xsimd::select(good, batch(1.0F), batch(0.0F)).store_aligned(flags);
    for (std::size_t l = 0; l < LANES; ++l) written += flags[l] != 0.0F ? 1U : 0U;
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
