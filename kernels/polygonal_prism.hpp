#pragma once
/// @file
/// @brief Polygonal prism (specs/PIPELINE.md section 4): points above the support polygon.
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/convex_hull.hpp"
#include "kernels/crop.hpp"
#include "kernels/plane_distance.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief The prism: plane, its basis, the hull vertices (u, v) counter-clockwise, height range.
struct Prism {
  Plane plane;
  PlaneBasis basis;
  std::span<const double> hull_u;  ///< counter-clockwise convex polygon (convex_hull_2d order)
  std::span<const double> hull_v;
  float h_min =
      0.005F;  ///< signed height range, metres, along the plane normal (positive toward the sensor)
  float h_max = 0.5F;
  AxisBox
      box{};  ///< points must also lie in this box (inclusive; the chain's ROI); default: no limit
};

/// @brief mask[i] = 1 when point i has signed height normal . p + d in [h_min, h_max], lies in
/// prism.box and its projection lies inside (or on) the hull polygon; 0 otherwise (NaN points,
/// hulls of < 3 vertices).
/// @p heights receives the signed heights (SIMD plane_signed_distance).
/// @pre mask.size() and heights.size() >= points.size(). @return the number of points kept.
/// @note Allocation-free, thread-safe. SIMD: heights as plane_signed_distance computes them, in the
/// same pass as the rest (the frame is read once); the polygon test runs
/// only on the points whose height is in range, in float against the hull's half-planes (SIMD over
/// points, loop over edges); a point within the float rounding slack of an edge line takes the
/// exact double test of the twin, and every other point is at least that slack inside or outside,
/// where the double test cannot disagree. So for equal heights the masks are equal; the only
/// tolerance against the twin is the plane_distance.hpp one, for points whose height is within 1e-6
/// x (|p| + |d|) of h_min or h_max. Hulls of more than 256 vertices take the exact test for every
/// in-range point.
std::size_t polygonal_prism(PointsView points, const Prism& prism, std::span<float> heights,
                            std::span<std::uint8_t> mask) noexcept;
/// @brief Scalar reference twin of polygonal_prism().
std::size_t polygonal_prism_scalar(PointsView points, const Prism& prism, std::span<float> heights,
                                   std::span<std::uint8_t> mask) noexcept;

/// @brief Whether (u, v) lies inside or on the convex counter-clockwise polygon (O(log n) fan
/// search).
bool inside_convex_polygon(std::span<const double> hu, std::span<const double> hv, double u,
                           double v) noexcept;

}  // namespace orthoflow::kernels
