#pragma once
/// @file
/// @brief Surface normals at chosen points of an unorganized object view (the spin images' axes,
/// thesis chapter 4), by PCL's `NormalEstimation` rule with a radius search: the neighbours are the
/// points p with |p - q|^2 <= r^2 (q itself included), their covariance about their centroid gives
/// the normal as the eigenvector of its smallest eigenvalue, and the normal is flipped to face the
/// viewpoint (PCL's `flipNormalTowardsViewpoint`: (v - q) . n >= 0). Fewer than `min_neighbours`
/// finite neighbours, or a point that is not finite, gives a NaN normal.
///
/// The search is brute force (O(points) per chosen point): object views hold a few thousand points
/// and the keypoints a few hundred, so a k-d tree would not pay for itself here.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

struct PointNormalParams {
  float radius = 0.02F;                     ///< metres: the neighbourhood (2 voxels of 1 cm)
  std::uint32_t min_neighbours = 3;         ///< below this the normal is NaN (a plane needs three)
  std::array<float, 3> viewpoint{0, 0, 0};  ///< the sensor's origin in the view's frame
};

/// @brief Why point_normals() refused to run.
struct PointNormalError {
  enum class Code : std::uint8_t {
    INVALID_RADIUS,    ///< not finite or <= 0
    BAD_INDEX,         ///< an index at or past the point count
    OUTPUT_TOO_SMALL,  ///< the output holds fewer points than the view
  };
  Code code = Code::INVALID_RADIUS;
  double value = 0.0;
  [[nodiscard]] std::string to_string() const;
};

/// @brief The normal of every point named in @p at, written at that point's index of @p out (one
/// slot per point of @p points; the other slots are left as they are).
/// @return how many of them are finite, or an error (nothing written).
/// @note Stateless, thread-safe, allocation-free; double-precision covariance, deterministic.
[[nodiscard]] Result<std::size_t, PointNormalError> point_normals(PointsView points,
                                                                  std::span<const std::uint32_t> at,
                                                                  const PointNormalParams& params,
                                                                  PointsSpan out) noexcept;

}  // namespace orthoflow::kernels
