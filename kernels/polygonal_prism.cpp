#include "kernels/polygonal_prism.hpp"

#include "memory_pool/assert.hpp"

namespace orthoflow::kernels {

namespace {

double cross_at(std::span<const double> hu, std::span<const double> hv, std::size_t a, std::size_t b, double u,
                double v) {
  return (hu[b] - hu[a]) * (v - hv[a]) - (hv[b] - hv[a]) * (u - hu[a]);
}

/// The polygon test for the points whose height is in range (heights already computed).
std::size_t mask_by_polygon(PointsView pts, const Prism& prism, std::span<const float> heights,
                            std::span<std::uint8_t> mask) {
  const PlaneBasis& b = prism.basis;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const float h = heights[i];
    bool keep = h >= prism.h_min && h <= prism.h_max;  // false for NaN
    if (keep) {
      const double q[3] = {pts.x[i] - b.origin[0], pts.y[i] - b.origin[1], pts.z[i] - b.origin[2]};
      keep = inside_convex_polygon(prism.hull_u, prism.hull_v, q[0] * b.u[0] + q[1] * b.u[1] + q[2] * b.u[2],
                                   q[0] * b.v[0] + q[1] * b.v[1] + q[2] * b.v[2]);
    }
    mask[i] = keep ? 1 : 0;
    kept += keep ? 1U : 0U;
  }
  return kept;
}

}  // namespace

bool inside_convex_polygon(std::span<const double> hu, std::span<const double> hv, double u, double v) noexcept {
  const std::size_t n = hu.size();
  if (n < 3) { return false; }
  // Fan from vertex 0: outside the wedge (0,1)..(0,n-1) means outside; else binary-search the sector.
  if (cross_at(hu, hv, 0, 1, u, v) < 0.0 || cross_at(hu, hv, 0, n - 1, u, v) > 0.0) { return false; }
  std::size_t lo = 1, hi = n - 1;
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (cross_at(hu, hv, 0, mid, u, v) >= 0.0 ? lo : hi) = mid;
  }
  return cross_at(hu, hv, lo, hi, u, v) >= 0.0;
}

std::size_t polygonal_prism(PointsView points, const Prism& prism, std::span<float> heights,
                            std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= points.size() && heights.size() >= points.size(), "polygonal_prism: spans too small");
  plane_signed_distance(points, prism.plane, heights);
  return mask_by_polygon(points, prism, heights, mask);
}

std::size_t polygonal_prism_scalar(PointsView points, const Prism& prism, std::span<float> heights,
                                   std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= points.size() && heights.size() >= points.size(), "polygonal_prism: spans too small");
  plane_signed_distance_scalar(points, prism.plane, heights);
  return mask_by_polygon(points, prism, heights, mask);
}

}  // namespace orthoflow::kernels
