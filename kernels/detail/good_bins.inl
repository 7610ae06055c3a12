#pragma once
// SIMD bodies of GOOD's two passes: frame statistics (AABB + sign counts) and the three
// projections. Lane-wise transform and bin indices; the histogram increments stay scalar (scatter
// has no SIMD win).
#include <limits>

#include "kernels/detail/good_kernel.hpp"

namespace orthoflow::kernels::detail {

namespace good_simd {

template <class B>
struct Q {
  B x, y, z;
};

template <class B>
Q<B> transform(const GoodTransform& t, const float* px, const float* py, const float* pz) noexcept {
  const B dx = B::load_unaligned(px) - B(t.c[0]);
  const B dy = B::load_unaligned(py) - B(t.c[1]);
  const B dz = B::load_unaligned(pz) - B(t.c[2]);
  Q<B> q;
  // (r0 dx + r1 dy) + r2 dz: the grouping of good_transform_point().
  q.x = (B(t.r[0][0]) * dx + B(t.r[0][1]) * dy) + B(t.r[0][2]) * dz;
  q.y = (B(t.r[1][0]) * dx + B(t.r[1][1]) * dy) + B(t.r[1][2]) * dz;
  q.z = (B(t.r[2][0]) * dx + B(t.r[2][1]) * dy) + B(t.r[2][2]) * dz;
  return q;
}

// Lane-wise extremes -> scalar extremes (order-free, so the result equals the scalar pass).
template <class B>
void reduce_extremes(const B (&lo)[3], const B (&hi)[3], GoodStats& s) noexcept {
  alignas(64) float buf[B::size];
  for (std::size_t a = 0; a < 3; ++a) {
    s.min[a] = std::numeric_limits<float>::infinity();
    s.max[a] = -std::numeric_limits<float>::infinity();
    lo[a].store_unaligned(buf);
    for (const float v : buf) { s.min[a] = std::min(s.min[a], v); }
    hi[a].store_unaligned(buf);
    for (const float v : buf) { s.max[a] = std::max(s.max[a], v); }
  }
}

}  // namespace good_simd

template <class Arch>
GoodStats GoodStatsKernel::operator()(Arch /*arch*/, PointsView points, const GoodTransform& t,
                                      float threshold) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = points.size();
  const float inf = std::numeric_limits<float>::infinity();
  batch lo[3] = {batch(inf), batch(inf), batch(inf)};
  batch hi[3] = {batch(-inf), batch(-inf), batch(-inf)};
  batch cnt[4] = {batch(0.0F), batch(0.0F), batch(0.0F),
                  batch(0.0F)};  // pos x, neg x, pos y, neg y
  GoodStats s;
  const auto flush = [&] {
    for (std::size_t k = 0; k < 2; ++k) {
      s.pos[k] += static_cast<std::size_t>(xsimd::hadd(cnt[2 * k]));
      s.neg[k] += static_cast<std::size_t>(xsimd::hadd(cnt[2 * k + 1]));
    }
    for (auto& c : cnt) { c = batch(0.0F); }
  };
  std::size_t i = 0;
  std::size_t since_flush = 0;
  const batch one(1.0F), zero(0.0F), tp(threshold), tn(-threshold);
  for (; i + LANES <= n; i += LANES) {
    const batch x = batch::load_unaligned(points.x.data() + i);
    const batch y = batch::load_unaligned(points.y.data() + i);
    const batch z = batch::load_unaligned(points.z.data() + i);
    const auto ok = ((x - x) == zero) && ((y - y) == zero) && ((z - z) == zero);  // all finite
    const auto q = good_simd::transform<batch>(t, points.x.data() + i, points.y.data() + i,
                                               points.z.data() + i);
    const batch qs[3] = {q.x, q.y, q.z};
    for (std::size_t a = 0; a < 3; ++a) {
      lo[a] = xsimd::select(ok, xsimd::min(lo[a], qs[a]), lo[a]);
      hi[a] = xsimd::select(ok, xsimd::max(hi[a], qs[a]), hi[a]);
    }
    for (std::size_t a = 0; a < 2; ++a) {
      cnt[2 * a] = cnt[2 * a] + xsimd::select(ok && (qs[a] > tp), one, zero);
      cnt[2 * a + 1] = cnt[2 * a + 1] + xsimd::select(ok && (qs[a] < tn), one, zero);
    }
    if (++since_flush == (1U << 20)) {  // float counters are exact up to 2^24 per lane
      flush();
      since_flush = 0;
    }
  }
  flush();
  good_simd::reduce_extremes(lo, hi, s);
  good_stats_scalar(points, t, threshold, i, n, s);
  return s;
}

template <class Arch>
void GoodBinKernel::operator()(Arch /*arch*/, PointsView points, const GoodBinParams& p,
                               std::span<std::uint32_t> counts) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = points.size();
  const float nf = static_cast<float>(p.bins);
  const float nn = nf * nf;  // slots stay below 3 * 256^2 + 3 < 2^24: exact in float
  const batch half(p.half), width(p.width), lo(-1.0F), hi(nf), nb(nf);
  // Row and column axis of each canonical view, and its offset (good_slot()).
  constexpr std::size_t ROW[3] = {1, 0, 0};
  constexpr std::size_t COL[3] = {2, 2, 1};
  alignas(64) std::int32_t slot[3][LANES];
  std::size_t i = 0;
  for (; i + LANES <= n; i += LANES) {
    const auto q = good_simd::transform<batch>(p.t, points.x.data() + i, points.y.data() + i,
                                               points.z.data() + i);
    const batch qs[3] = {q.x, q.y, q.z};
    batch k[3];
    xsimd::batch_bool<float, Arch> ok[3];
    for (std::size_t a = 0; a < 3; ++a) {
      const batch f =
          (qs[a] + half) / width;  // the division of good_bin_scalar(), exact IEEE in both
      ok[a] = (f > lo) && (f < hi);
      k[a] = xsimd::trunc(f);  // (-1, 0) -> -0 -> bin 0, as the reference
    }
    for (std::size_t v = 0; v < 3; ++v) {
      const float base = static_cast<float>(v) * nn;
      const batch cell = batch(base) + k[ROW[v]] * nb + k[COL[v]];
      const batch s =
          xsimd::select(ok[ROW[v]] && ok[COL[v]], cell, batch(3.0F * nn + static_cast<float>(v)));
      xsimd::to_int(s).store_unaligned(slot[v]);
    }
    for (std::size_t l = 0; l < LANES; ++l) {
      ++counts[static_cast<std::size_t>(slot[0][l])];
      ++counts[static_cast<std::size_t>(slot[1][l])];
      ++counts[static_cast<std::size_t>(slot[2][l])];
    }
  }
  good_bin_range_scalar(points, p, i, n, counts);
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template orthoflow::kernels::detail::GoodStats
orthoflow::kernels::detail::GoodStatsKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView, const orthoflow::kernels::detail::GoodTransform&,
    float) const noexcept;
template void orthoflow::kernels::detail::GoodBinKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView, const orthoflow::kernels::detail::GoodBinParams&,
    std::span<std::uint32_t>) const noexcept;
#endif
