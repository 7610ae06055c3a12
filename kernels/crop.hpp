#pragma once
/// @file
/// @brief NaN removal and region-of-interest boxes (axis-aligned and oriented) as a per-point keep
/// mask, plus compaction (dense output with source indices) or masking in place of organization.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Axis-aligned box, bounds inclusive. The default box keeps every finite point.
struct AxisBox {
  std::array<float, 3> min{-3.4e38F, -3.4e38F, -3.4e38F};
  std::array<float, 3> max{3.4e38F, 3.4e38F, 3.4e38F};
};

/// @brief Oriented box: a point p is inside when |axis_k . (p - center)| <= half_extent[k] for the
/// three unit rows axis_k of @p axes (row-major 3x3, orthonormal).
struct OrientedBox {
  std::array<float, 3> center{};
  std::array<float, 9> axes{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<float, 3> half_extent{};
};

/// @brief mask[i] = 1 when x, y, z of point i are finite and inside @p box (inclusive), else 0.
/// NaN removal alone is crop_box_mask with the default AxisBox (it also drops +-Inf).
/// @pre mask.size() >= in.size(). @return the number of points kept.
/// @note Stateless, thread-safe; SIMD and scalar masks are equal (comparisons only).
std::size_t crop_box_mask(PointsView in, const AxisBox& box, std::span<std::uint8_t> mask) noexcept;
/// @brief Scalar reference twin of crop_box_mask().
std::size_t crop_box_mask_scalar(PointsView in, const AxisBox& box,
                                 std::span<std::uint8_t> mask) noexcept;

/// @brief mask[i] = 1 when point i is finite and inside the oriented @p box.
/// @pre mask.size() >= in.size(). @return the number of points kept.
/// @note Tolerance: the SIMD variant may fuse multiply-adds, so a point within 1e-6 x (|p| +
/// |center|) of a face may be classified differently from the scalar twin; all others agree.
std::size_t crop_oriented_mask(PointsView in, const OrientedBox& box,
                               std::span<std::uint8_t> mask) noexcept;
/// @brief Scalar reference twin of crop_oriented_mask().
std::size_t crop_oriented_mask_scalar(PointsView in, const OrientedBox& box,
                                      std::span<std::uint8_t> mask) noexcept;

/// @brief Copies the points whose mask byte is non-zero to the front of @p out, in input order, and
/// their input indices to @p indices (skipped when @p indices is empty).
/// @pre out.size() and (if not empty) indices.size() >= the number of set mask bytes; mask.size()
/// >= in.size().
/// @return the number of points written. @note A copy loop with no SIMD variant (memory bound).
std::size_t compact_masked(PointsView in, std::span<const std::uint8_t> mask, PointsSpan out,
                           std::span<std::uint32_t> indices) noexcept;

/// @brief Keeps organization: out[i] = in[i] where mask[i] != 0, NaN elsewhere. @p out may alias @p
/// in.
/// @pre out.size() == in.size() <= mask.size(). @return the number of kept points.
std::size_t mask_organized(PointsView in, std::span<const std::uint8_t> mask,
                           PointsSpan out) noexcept;

}  // namespace orthoflow::kernels
