#pragma once
/// @file
/// @brief Dominant plane by RANSAC (specs/PIPELINE.md section 3): hypotheses from 3 distinct
/// non-collinear points drawn by the portable Rng, score = points within tau, optional early stop
/// at a stated confidence, then a least-squares (PCA) refit on the inliers and the final inlier
/// indices.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "core/result.hpp"
#include "kernels/plane_distance.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief RANSAC settings; the defaults are the thesis's (tau 0.02 m, 200 iterations, no early
/// stop).
struct RansacParams {
  float tau = 0.02F;                   ///< inlier distance, metres
  std::uint32_t max_iterations = 200;  ///< hypotheses drawn at most
  double confidence = 0.0;  ///< in (0, 1): stop when this sure of an outlier-free sample; 0: never
  std::uint64_t seed = 0x0f5eed5eedULL;  ///< Rng seed: same seed, same plane
  /// Gravity prior: when `up` is a unit vector (not all zero), a hypothesis whose normal is more
  /// than max_tilt_deg from it (either sign) is redrawn like a degenerate one, never scored: only
  /// near-level planes are found, and the non-level draws cost no scoring pass. A refit plane
  /// beyond the angle is no plane (NO_HYPOTHESIS).
  std::array<float, 3> up{};
  float max_tilt_deg = 90.0F;
};

/// @brief The refit plane (unit normal oriented so that d >= 0, i.e. the origin, where the sensor
/// sits, is on the positive side), its inlier count and the hypotheses drawn.
struct RansacPlane {
  Plane plane;
  std::size_t inliers = 0;
  std::uint32_t iterations = 0;
};

/// @brief Why ransac_plane() found no plane.
struct RansacError {
  enum class Code : std::uint8_t {
    BAD_PARAMS,        ///< tau not finite or < 0, max_iterations 0, or confidence outside [0, 1)
    TOO_FEW_POINTS,    ///< fewer than 3 finite points
    NO_HYPOTHESIS,     ///< every draw was degenerate (all points coincident or collinear)
    OUTPUT_TOO_SMALL,  ///< inliers_out shorter than the inlier count
  };
  Code code = Code::BAD_PARAMS;
  double value = 0.0;
  [[nodiscard]] std::string to_string() const;
};

/// @brief Fits the dominant plane of @p points and writes its inlier indices (ascending) to the
/// front of @p inliers_out. NaN points are never drawn nor counted.
/// @pre points.size() <= UINT32_MAX. @note Allocation-free, thread-safe, deterministic for a given
/// seed and input on one machine; the SIMD inlier count may differ from the scalar one for points
/// at distance ~tau (plane_distance.hpp tolerance), which can change the hypothesis kept on another
/// CPU.
[[nodiscard]] Result<RansacPlane, RansacError> ransac_plane(
    PointsView points, const RansacParams& params, std::span<std::uint32_t> inliers_out) noexcept;
/// @brief Scalar reference twin of ransac_plane() (scalar inlier counting).
[[nodiscard]] Result<RansacPlane, RansacError> ransac_plane_scalar(
    PointsView points, const RansacParams& params, std::span<std::uint32_t> inliers_out) noexcept;

/// @brief Least-squares plane through @p indices of @p points (smallest-eigenvalue eigenvector of
/// the covariance, double precision), oriented so that d >= 0. @pre indices non-empty, finite
/// points.
Plane fit_plane(PointsView points, std::span<const std::uint32_t> indices) noexcept;

}  // namespace orthoflow::kernels
