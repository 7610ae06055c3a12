#pragma once
/// @file
/// @brief Per-pixel surface normals of an organized cloud from its pixel grid (the crowded-scene
/// mode of the object stage, docs/SEGMENTATION.md): at pixel (r, c), the cross product of the
/// central differences P(r+s, c) - P(r-s, c) and P(r, c+s) - P(r, c-s), normalised and turned
/// toward the sensor (n . P < 0). NaN when a neighbour is missing, lies outside the image, or
/// steps in depth by more than depth_change x z of the centre (a depth edge, not a surface).
#include <cstdint>
#include <span>

#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

struct NormalParams {
  std::uint32_t offset = 3;    ///< s, pixels: the half-width of the central differences
  float depth_change = 0.03F;  ///< largest |z_neighbour - z| / z of a neighbour that counts
};

/// @brief Rows [begin, end) of an image.
struct RowRange {
  std::uint32_t begin = 0;
  std::uint32_t end = UINT32_MAX;  ///< clipped to the image height
};

/// @brief Writes the normal of every pixel of @p rows of @p cloud to @p out (NaN where there is
/// none); other rows of @p out are left as they are.
/// @pre cloud organized, cloud.points.size() == width * height <= out.size(); params.offset >= 1.
/// @return the pixels with a normal. @note Stateless, thread-safe, allocation-free. Every SIMD
/// variant equals the scalar twin bit for bit (IEEE operations only, compiled without multiply-add
/// contraction), so x86 and ARM agree.
std::size_t organized_normals(CloudView cloud, const NormalParams& params, PointsSpan out,
                              RowRange rows = {}) noexcept;
/// @brief Writes the normal of each of @p pixels (flat indices, any order, repeats allowed) of @p
/// cloud to @p out, the value organized_normals() gives there (bit for bit); other pixels of @p
/// out are left as they are. For a few scattered pixels, where a band of rows would cost more.
/// @pre as organized_normals(); every index < width * height. @return the pixels with a normal
/// (repeats counted). @note Stateless, thread-safe, allocation-free.
std::size_t organized_normals_at(CloudView cloud, const NormalParams& params, PointsSpan out,
                                 std::span<const std::uint32_t> pixels) noexcept;
/// @brief Scalar reference twin of organized_normals().
std::size_t organized_normals_scalar(CloudView cloud, const NormalParams& params, PointsSpan out,
                                     RowRange rows = {}) noexcept;

}  // namespace orthoflow::kernels
