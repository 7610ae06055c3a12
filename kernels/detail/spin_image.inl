#pragma once
// SIMD body of spin_images(), in two passes per chunk of neighbours (compiled with
// -ffp-contract=off, so every operation rounds as the scalar twin's does):
// 1. float batches of points: the neighbour test and d . n in the twin's operation order; for the
//    neighbours that pass the support angle (scalar, per neighbour), |d| by std::sqrt, collected in
//    order;
// 2. double batches of those neighbours: PCL's binning (cosine, alpha, beta, the cylinder, cells,
//    the border rule, the four bilinear weights) in the twin's operations, then the weights are
//    added to the image one neighbour at a time, in order. The image equals the twin's bit for bit.
#include <array>
#include <cmath>

#include "kernels/detail/spin_image_kernel.hpp"

namespace orthoflow::kernels::detail {

namespace {

constexpr std::size_t SPIN_CHUNK =
    64;  // neighbours binned per pass (a multiple of every lane count)

struct SpinChunk {
  std::array<double, SPIN_CHUNK> norm{}, dot{};
  std::size_t size = 0;
};

// Pass 2 over chunk entries [0, size): batches of double lanes, the rest by the scalar rule.
template <class Arch>
void bin_chunk(const SpinSetup& s, const SpinChunk& c, double* acc) noexcept {
  using batch = xsimd::batch<double, Arch>;
  constexpr std::size_t LANES = batch::size;
  const batch one(1.0), minus_one(-1.0), zero(0.0), bin(s.bin), limit(s.limit);
  const batch self(10 * std::numeric_limits<double>::epsilon());
  const batch eps(std::numeric_limits<double>::epsilon());
  const auto wd = static_cast<double>(s.width);
  const batch width(wd), last(wd - 1.0);
  alignas(64) std::array<double, LANES> keep{}, ab{}, bb{}, w00{}, w10{}, w01{}, w11{};
  std::size_t e = 0;
  for (; e + LANES <= c.size; e += LANES) {
    const batch dn = batch::load_unaligned(c.norm.data() + e);
    const batch dot = batch::load_unaligned(c.dot.data() + e);
    batch cos = dot / dn;
    cos = xsimd::select(cos < one, cos, one);  // std::min(1.0, c): NaN becomes 1
    cos = xsimd::select(minus_one < cos, cos, minus_one);
    batch beta = dn * cos;
    batch alpha = dn * xsimd::sqrt(one - cos * cos);
    const auto in = !(xsimd::abs(dn) < self) && !(xsimd::abs(beta) >= limit) && !(alpha >= limit);
    batch a_bin = xsimd::floor(alpha / bin);
    batch b_bin = xsimd::floor(beta / bin);  // beta_bin - W
    const auto a_edge = a_bin == width;
    a_bin = xsimd::select(a_edge, last, a_bin);
    alpha = xsimd::select(a_edge, bin * (a_bin + one) - eps, alpha);
    const auto b_edge = b_bin == width;
    b_bin = xsimd::select(b_edge, last, b_bin);
    beta = xsimd::select(b_edge, bin * (b_bin + one) - eps, beta);
    const batch a = alpha / bin - a_bin;
    const batch b = beta / bin - b_bin;
    xsimd::select(in, one, zero).store_aligned(keep.data());
    a_bin.store_aligned(ab.data());
    b_bin.store_aligned(bb.data());
    ((one - a) * (one - b)).store_aligned(w00.data());
    (a * (one - b)).store_aligned(w10.data());
    ((one - a) * b).store_aligned(w01.data());
    (a * b).store_aligned(w11.data());
    for (std::size_t l = 0; l < LANES; ++l) {
      if (keep[l] == 0.0) continue;
      const int alpha_bin = static_cast<int>(ab[l]);
      const int beta_bin = static_cast<int>(bb[l]) + static_cast<int>(s.width);
      if (alpha_bin < 0 || beta_bin < 0) continue;  // as the scalar rule
      spin_scatter(s, acc, alpha_bin, beta_bin, w00[l], w10[l], w01[l], w11[l]);
    }
  }
  for (; e < c.size; ++e)
    spin_bin(s, static_cast<float>(c.norm[e]), static_cast<float>(c.dot[e]), acc);
}

}  // namespace

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
  alignas(64) float dot[LANES];
  alignas(64) float dist2[LANES];
  SpinChunk chunk;
  for (; i + LANES <= n; i += LANES) {
    const batch dx = batch::load_unaligned(points.x.data() + i) - kx;
    const batch dy = batch::load_unaligned(points.y.data() + i) - ky;
    const batch dz = batch::load_unaligned(points.z.data() + i) - kz;
    const batch d2 = dx * dx + dy * dy + dz * dz;
    if (!xsimd::any(d2 < r2)) continue;
    d2.store_aligned(dist2);
    (dx * nx + dy * ny + dz * nz).store_aligned(dot);
    for (std::size_t l = 0; l < LANES; ++l) {
      if (!(dist2[l] < s.radius2)) continue;
      ++found;
      if (!spin_angle_ok(s, k, normals, i + l)) continue;
      // |d| by std::sqrt, one neighbour at a time: xsimd 8.1's float sqrt on neon64 is an
      // estimate refined by Newton steps, not the correctly rounded root the twin takes.
      chunk.norm[chunk.size] = static_cast<double>(std::sqrt(dist2[l]));
      chunk.dot[chunk.size] = static_cast<double>(dot[l]);
      if (++chunk.size == SPIN_CHUNK) {
        bin_chunk<Arch>(s, chunk, acc);
        chunk.size = 0;
      }
    }
  }
  bin_chunk<Arch>(s, chunk, acc);
  return found + spin_range(s, k, points, normals, i, n, acc);
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template std::size_t orthoflow::kernels::detail::SpinNeighboursKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, const orthoflow::kernels::detail::SpinSetup&,
    const orthoflow::kernels::detail::SpinKey&, orthoflow::kernels::PointsView,
    orthoflow::kernels::PointsView, double*) const noexcept;
#endif
