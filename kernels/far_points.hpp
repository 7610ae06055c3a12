#pragma once
/// @file
/// @brief Far points of an object view: points much farther from the view's robust centre than its
/// bulk. One stray depth sample 100 m away (or at 1e30) would otherwise own the principal axes and
/// the bounding box, and the descriptor would collapse into one bin per projection or overflow. The
/// object frame is computed without them (compute_good(), FAR_POINTS_DROPPED).
///
/// Rule: the centre c is the coordinate-wise median and r the 90th-percentile distance to c, both
/// estimated on at most FAR_POINT_SAMPLES finite points taken at an even stride; a finite point is
/// far when |p - c| > max(FAR_POINT_FACTOR * r, FAR_POINT_FLOOR_M). So up to a tenth of a view may
/// be stray and still be found, a view whose bulk is split in two parts (a mug and its handle, two
/// ends of a band) keeps both, nothing within FAR_POINT_FLOOR_M of the centre is ever far, and a
/// view with fewer than FAR_POINT_MIN_SAMPLES finite samples has no far point (too few to judge).
#include <array>
#include <cstddef>

#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Points sampled to estimate the centre and the median radius.
inline constexpr std::size_t FAR_POINT_SAMPLES = 255;
/// @brief Fewer finite samples than this: nothing is far.
inline constexpr std::size_t FAR_POINT_MIN_SAMPLES = 20;
/// @brief A point is far beyond this many 90th-percentile radii ...
inline constexpr double FAR_POINT_FACTOR = 10.0;
/// @brief ... and never within this distance of the centre, in metres.
inline constexpr double FAR_POINT_FLOOR_M = 0.10;

/// @brief Where the bulk of a view is, and how many of its finite points lie far from it.
struct FarPoints {
  std::array<double, 3> centre{};  ///< coordinate-wise median of the sample
  double keep_radius = 0.0;  ///< max(FAR_POINT_FACTOR * 90th-percentile radius, FAR_POINT_FLOOR_M);
                             ///< infinite when the sample was too small
  std::size_t count = 0;     ///< finite points farther than keep_radius from centre
};

/// @brief Finds the far points of @p points (non-finite points are neither sampled nor far).
/// @note Scalar (the counting loop auto-vectorises), no allocation, deterministic on every
/// architecture: the sample is a fixed stride, quantiles by std::nth_element on fixed arrays in
/// double, the per-point test in IEEE float without contraction.
[[nodiscard]] FarPoints find_far_points(PointsView points) noexcept;

/// @brief Whether point @p i of @p points is far by @p far.
[[nodiscard]] bool is_far_point(PointsView points, std::size_t i, const FarPoints& far) noexcept;

/// @brief Copies the points of @p points that are not far (finite or not, in order) into @p out.
/// @pre out holds at least points.size() - far.count points. @return points written.
std::size_t copy_near_points(PointsView points, const FarPoints& far, PointsSpan out) noexcept;

}  // namespace orthoflow::kernels
