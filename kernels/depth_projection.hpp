#pragma once
/// @file
/// @brief Kinect v1 raw 11-bit disparity to an organized XYZ cloud (specs/KINECT_V1.md section 8).
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Entries of a raw-disparity lookup table (11 bits).
inline constexpr std::size_t DISPARITY_TABLE_SIZE = 2048;

/// @brief Pinhole intrinsics of the depth image.
struct DepthCamera {
  float fx = 575.8F;
  float fy = 575.8F;
  float cx = 319.5F;
  float cy = 239.5F;
};

/// @brief Fills @p table_m with the reciprocal-linear fit Z = 1 / (raw * -0.0030711016
/// + 3.3309495161) (KINECT_V1.md 8.1), in metres; 0 ("no reading") for raw 2047 and for raw >= 1080
/// (near the pole). A device table (simulation::make_depth_table) can be used instead. @note
/// Deterministic.
void fill_disparity_table_reciprocal(std::span<float, DISPARITY_TABLE_SIZE> table_m) noexcept;

/// @brief Back-projects a width x height raw image: z = table[raw & 0x7FF], x = (u - cx) / fx * z,
/// y = (v - cy) / fy * z; pixels whose table entry is not > 0 become NaN in x, y and z.
/// @pre raw.size() == width * height == out.size(); table entries are finite.
/// @return the number of valid (finite) points written. @note Stateless and thread-safe. The SIMD
/// variant equals the scalar twin bit for bit (products only, no fused multiply-add possible).
std::size_t depth_to_points(std::span<const std::uint16_t> raw, std::uint32_t width,
                            std::uint32_t height,
                            std::span<const float, DISPARITY_TABLE_SIZE> table_m,
                            const DepthCamera& camera, PointsSpan out) noexcept;
/// @brief Scalar reference twin of depth_to_points().
std::size_t depth_to_points_scalar(std::span<const std::uint16_t> raw, std::uint32_t width,
                                   std::uint32_t height,
                                   std::span<const float, DISPARITY_TABLE_SIZE> table_m,
                                   const DepthCamera& camera, PointsSpan out) noexcept;

}  // namespace orthoflow::kernels
