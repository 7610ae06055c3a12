#pragma once
// Declarations of the polygonal-prism SIMD functor; body in polygonal_prism.inl (one TU per arch).
#include <array>
#include <cmath>

#include "kernels/detail/plane_distance_kernel.hpp"
#include "kernels/polygonal_prism.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

/// The hull as float half-planes for the SIMD prefilter: a point (u, v) of the plane is inside edge
/// k when a[k] u + b[k] v + c[k] >= 0 (unit edge normals pointing inward), and the basis in float.
/// A lane whose smallest edge distance is within slack * (|x| + |y| + |z| + scale) of 0, which
/// bounds the float rounding of the projection and of the coefficients, is decided by the exact
/// double test.
struct PrismEdges {
  static constexpr std::size_t MAX_EDGES =
      256;  ///< larger hulls take the exact path for every point
  std::array<float, MAX_EDGES> a{}, b{}, c{};
  std::size_t count = 0;
  std::array<float, 3> origin{}, u{}, v{};
  float slack = 0.0F, scale = 0.0F;
};

/// The hull of @p prism as PrismEdges; false when the float prefilter cannot be used (fewer than 3
/// or more than MAX_EDGES vertices, a zero-length edge, non-finite values): every point then takes
/// the exact test.
bool make_prism_edges(const Prism& prism, PrismEdges& e) noexcept;

struct PrismPolygonKernel {
  template <class Arch>
  std::size_t operator()(Arch arch, PointsView points, const Prism& prism, const PrismEdges& edges,
                         std::span<float> heights, std::span<std::uint8_t> mask) const noexcept;
};

/// The exact polygon rule for point i (projection inside the hull, in double): the scalar
/// twin's, the SIMD tail's and the SIMD body's for lanes the float prefilter cannot decide.
inline bool prism_inside_exact(PointsView pts, const Prism& prism, std::size_t i) noexcept {
  const PlaneBasis& b = prism.basis;
  const double q[3] = {pts.x[i] - b.origin[0], pts.y[i] - b.origin[1], pts.z[i] - b.origin[2]};
  return inside_convex_polygon(prism.hull_u, prism.hull_v,
                               q[0] * b.u[0] + q[1] * b.u[1] + q[2] * b.u[2],
                               q[0] * b.v[0] + q[1] * b.v[1] + q[2] * b.v[2]);
}

/// Scalar rule for points [begin, end) once heights are known.
inline std::size_t prism_mask_range(PointsView pts, const Prism& prism,
                                    std::span<const float> heights, std::uint8_t* mask,
                                    std::size_t begin, std::size_t end) noexcept {
  std::size_t kept = 0;
  for (std::size_t i = begin; i < end; ++i) {
    const float h = heights[i];
    const AxisBox& box = prism.box;
    const bool in_box = pts.x[i] >= box.min[0] && pts.x[i] <= box.max[0] &&
                        pts.y[i] >= box.min[1] && pts.y[i] <= box.max[1] &&
                        pts.z[i] >= box.min[2] && pts.z[i] <= box.max[2];
    const bool keep = h >= prism.h_min && h <= prism.h_max && in_box &&
                      prism_inside_exact(pts, prism, i);  // NaN: false
    mask[i] = keep ? 1 : 0;
    kept += keep ? 1U : 0U;
  }
  return kept;
}

}  // namespace orthoflow::kernels::detail
