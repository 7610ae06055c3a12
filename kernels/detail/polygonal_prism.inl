#pragma once
// SIMD body of polygonal_prism() after its setup: heights (written out), then lanes whose height is
// out of range are rejected a batch at a time; the others (box test, then) are projected on the
// plane in float and tested against every hull edge (SIMD over points, loop over edges). Lanes
// within the rounding slack of an edge take the exact double test, so the decision is the scalar
// twin's one (see polygonal_prism.hpp for the only caveat).
#include <limits>

#include "kernels/detail/polygonal_prism_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Arch>
std::size_t PrismPolygonKernel::operator()(Arch /*arch*/, PointsView pts, const Prism& prism,
                                           const PrismEdges& e, std::span<float> heights,
                                           std::span<std::uint8_t> mask) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = pts.size();
  const batch h_min(prism.h_min), h_max(prism.h_max);
  const Plane& pl = prism.plane;
  const batch na(pl.normal[0]), nb(pl.normal[1]), nc(pl.normal[2]), nd(pl.d);
  std::size_t kept = 0, i = 0;
  alignas(64) float code[LANES];
  for (; i + LANES <= n; i += LANES) {
    const batch x = batch::load_unaligned(pts.x.data() + i),
                y = batch::load_unaligned(pts.y.data() + i),
                z = batch::load_unaligned(pts.z.data() + i);
    const batch h =
        na * x + nb * y + nc * z + nd;  // plane_distance.inl's expression: the same heights
    h.store_unaligned(heights.data() + i);
    const auto in_range = (h >= h_min) && (h <= h_max);  // false for NaN
    if (xsimd::none(in_range)) {
      for (std::size_t l = 0; l < LANES; ++l) { mask[i + l] = 0; }
      continue;
    }
    const AxisBox& box = prism.box;
    const auto in_box = (x >= batch(box.min[0])) && (x <= batch(box.max[0])) &&
                        (y >= batch(box.min[1])) && (y <= batch(box.max[1])) &&
                        (z >= batch(box.min[2])) && (z <= batch(box.max[2]));
    const batch qx = x - batch(e.origin[0]), qy = y - batch(e.origin[1]),
                qz = z - batch(e.origin[2]);
    const batch u = qx * batch(e.u[0]) + qy * batch(e.u[1]) + qz * batch(e.u[2]);
    const batch v = qx * batch(e.v[0]) + qy * batch(e.v[1]) + qz * batch(e.v[2]);
    batch s_min(std::numeric_limits<float>::infinity());
    for (std::size_t k = 0; k < e.count; ++k) {
      s_min = xsimd::min(s_min, batch(e.a[k]) * u + batch(e.b[k]) * v + batch(e.c[k]));
    }
    const batch eps =
        batch(e.slack) * (xsimd::abs(x) + xsimd::abs(y) + xsimd::abs(z) + batch(e.scale));
    // 1: inside by more than the slack; 2: undecided (exact test); 0: out of range or outside.
    const batch decided = xsimd::select(s_min > eps, batch(1.0F),
                                        xsimd::select(s_min >= -eps, batch(2.0F), batch(0.0F)));
    xsimd::select(in_range && in_box, decided, batch(0.0F)).store_aligned(code);
    for (std::size_t l = 0; l < LANES; ++l) {
      const bool keep =
          code[l] == 1.0F || (code[l] == 2.0F && prism_inside_exact(pts, prism, i + l));
      mask[i + l] = keep ? 1 : 0;
      kept += keep ? 1U : 0U;
    }
  }
  for (std::size_t t = i; t < n; ++t) {
    heights[t] = plane_distance(pl, pts.x[t], pts.y[t], pts.z[t]);
  }
  return kept + prism_mask_range(pts, prism, heights, mask.data(), i, n);
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template std::size_t orthoflow::kernels::detail::PrismPolygonKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView, const orthoflow::kernels::Prism&,
    const orthoflow::kernels::detail::PrismEdges&, std::span<float>,
    std::span<std::uint8_t>) const noexcept;
#endif
