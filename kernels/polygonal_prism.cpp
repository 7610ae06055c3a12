#include "kernels/polygonal_prism.hpp"

#include <algorithm>
#include <cmath>

#include "core/assert.hpp"
#include "kernels/detail/polygonal_prism_kernel.hpp"

namespace orthoflow::kernels {

namespace {

double cross_at(std::span<const double> hu, std::span<const double> hv, std::size_t a,
                std::size_t b, double u, double v) {
  return (hu[b] - hu[a]) * (v - hv[a]) - (hv[b] - hv[a]) * (u - hu[a]);
}

}  // namespace

bool detail::make_prism_edges(const Prism& prism, PrismEdges& e) noexcept {
  const std::size_t n = prism.hull_u.size();
  if (n < 3 || n > PrismEdges::MAX_EDGES || prism.hull_v.size() != n) { return false; }
  double c_max = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t next = k + 1 == n ? 0 : k + 1;
    const double du = prism.hull_u[next] - prism.hull_u[k],
                 dv = prism.hull_v[next] - prism.hull_v[k];
    const double len = std::hypot(du, dv);
    if (!(len > 0.0) || !std::isfinite(len)) { return false; }
    const double a = -dv / len,
                 b = du / len;  // counter-clockwise: the inward normal is the left one
    const double c = -(a * prism.hull_u[k] + b * prism.hull_v[k]);
    e.a[k] = static_cast<float>(a), e.b[k] = static_cast<float>(b), e.c[k] = static_cast<float>(c);
    c_max = std::max(c_max, std::fabs(c));
  }
  e.count = n;
  double o_sum = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    e.origin[k] = static_cast<float>(prism.basis.origin[k]);
    e.u[k] = static_cast<float>(prism.basis.u[k]);
    e.v[k] = static_cast<float>(prism.basis.v[k]);
    o_sum += std::fabs(prism.basis.origin[k]);
  }
  // The float projection and edge distance of a point p err by at most a few ulps of |p|_1 +
  // |origin|_1 + |c|; 64 ulps (2^-18) of a bound 4x that sum leaves an ample margin (FMA
  // contraction only lowers it).
  e.slack = 0x1p-18F;
  e.scale = static_cast<float>(4.0 * (o_sum + c_max));
  return std::isfinite(e.scale);
}

bool inside_convex_polygon(std::span<const double> hu, std::span<const double> hv, double u,
                           double v) noexcept {
  const std::size_t n = hu.size();
  if (n < 3) { return false; }
  // Fan from vertex 0: outside the wedge (0,1)..(0,n-1) means outside; else binary-search the
  // sector.
  if (cross_at(hu, hv, 0, 1, u, v) < 0.0 || cross_at(hu, hv, 0, n - 1, u, v) > 0.0) {
    return false;
  }
  std::size_t lo = 1, hi = n - 1;
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (cross_at(hu, hv, 0, mid, u, v) >= 0.0 ? lo : hi) = mid;
  }
  return cross_at(hu, hv, lo, hi, u, v) >= 0.0;
}

std::size_t polygonal_prism(PointsView points, const Prism& prism, std::span<float> heights,
                            std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= points.size() && heights.size() >= points.size(),
            "polygonal_prism: spans too small");
  detail::PrismEdges edges;
  if (!detail::make_prism_edges(prism, edges)) {
    plane_signed_distance(points, prism.plane, heights);
    return detail::prism_mask_range(points, prism, heights, mask.data(), 0, points.size());
  }
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::PrismPolygonKernel{});
  return dispatched(points, prism, edges, heights, mask);  // computes the heights in the same pass
}

std::size_t polygonal_prism_scalar(PointsView points, const Prism& prism, std::span<float> heights,
                                   std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= points.size() && heights.size() >= points.size(),
            "polygonal_prism: spans too small");
  plane_signed_distance_scalar(points, prism.plane, heights);
  return detail::prism_mask_range(points, prism, heights, mask.data(), 0, points.size());
}

}  // namespace orthoflow::kernels
