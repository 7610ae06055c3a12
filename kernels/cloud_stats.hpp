#pragma once
/// @file
/// @brief Whole-cloud statistics: how many points are finite and their axis-aligned bounding box.
#include <array>
#include <cstddef>

#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Count of finite points and the axis-aligned box around them.
/// When finite == 0 the box is empty: min = +inf and max = -inf on every axis.
struct CloudStats {
  std::size_t finite = 0;
  std::array<float, 3> min{};
  std::array<float, 3> max{};
};

/// @brief Counts the points whose x, y and z are all finite and bounds them (NaN and +-Inf
/// skipped).
/// @pre x, y and z have equal lengths. @note Deterministic; the SIMD and scalar results are equal
/// bit for bit (min/max and counting are exact operations).
CloudStats cloud_stats(PointsView points) noexcept;
/// @brief Scalar reference twin of cloud_stats().
CloudStats cloud_stats_scalar(PointsView points) noexcept;

}  // namespace orthoflow::kernels
