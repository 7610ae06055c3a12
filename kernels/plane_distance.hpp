#pragma once
/// @file
/// @brief Point-to-plane distances: inlier counting (the RANSAC score) and signed heights (the
/// prism).
#include <array>
#include <cstddef>
#include <span>

#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief The plane normal . p + d = 0 with a unit normal.
struct Plane {
  std::array<float, 3> normal{0.0F, 0.0F, 1.0F};
  float d = 0.0F;
};

/// @brief Counts the points with |normal . p + d| <= tau (NaN points never count).
/// @pre tau >= 0. @note Stateless, thread-safe. Tolerance: the SIMD variant may fuse multiply-adds,
/// so a point whose distance is within 1e-6 x (|p| + |d|) of tau may count differently; all others
/// agree.
std::size_t count_plane_inliers(PointsView points, const Plane& plane, float tau) noexcept;
/// @brief Scalar reference twin of count_plane_inliers().
std::size_t count_plane_inliers_scalar(PointsView points, const Plane& plane, float tau) noexcept;

/// @brief out[i] = normal . p_i + d (NaN for NaN points). @pre out.size() >= points.size().
/// @return points.size(). @note Tolerance against the scalar twin: 1e-6 x (|p| + |d|) absolute.
std::size_t plane_signed_distance(PointsView points, const Plane& plane,
                                  std::span<float> out) noexcept;
/// @brief Scalar reference twin of plane_signed_distance().
std::size_t plane_signed_distance_scalar(PointsView points, const Plane& plane,
                                         std::span<float> out) noexcept;

}  // namespace orthoflow::kernels
