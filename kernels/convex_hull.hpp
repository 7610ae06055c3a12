#pragma once
/// @file
/// @brief The support polygon: 2-D convex hull of plane inliers expressed in a basis of the plane.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/plane_distance.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Orthonormal frame of a plane: origin = the plane point closest to (0,0,0), in-plane axes
/// u and v, and the plane normal n (u x v = n). Deterministic function of the plane.
struct PlaneBasis {
  std::array<double, 3> origin{};
  std::array<double, 3> u{};
  std::array<double, 3> v{};
  std::array<double, 3> n{};
};

/// @brief The basis of @p plane (u from the world axis least aligned with the normal).
PlaneBasis make_plane_basis(const Plane& plane) noexcept;

/// @brief (u, v) coordinates of the points @p indices of @p points projected on the plane.
/// @pre u.size() and v.size() >= indices.size(). @return indices.size().
std::size_t project_to_plane(PointsView points, std::span<const std::uint32_t> indices,
                             const PlaneBasis& basis, std::span<double> u,
                             std::span<double> v) noexcept;

/// @brief Convex hull of the 2-D points (u[i], v[i]) by Andrew's monotone chain after an
/// Akl-Toussaint octagon prefilter. Writes the hull vertex indices counter-clockwise, starting at
/// the lowest (u, v), without repeated, duplicate or collinear vertices. 1 or 2 vertices for
/// degenerate input.
/// @pre u.size() == v.size() <= UINT32_MAX; scratch.size() >= u.size(); hull_out.size() >= u.size()
/// + 1 (the chain needs one slot more than it returns). NaN coordinates are skipped.
/// @return the number of hull vertices. @note Allocation-free, deterministic (ties broken by
/// index).
std::size_t convex_hull_2d(std::span<const double> u, std::span<const double> v,
                           std::span<std::uint32_t> scratch,
                           std::span<std::uint32_t> hull_out) noexcept;

}  // namespace orthoflow::kernels
