#pragma once
/// @file
/// @brief Raw Kinect v1 disparity to metric depth from the device's own calibration
/// (specs/KINECT_V1.md 8.2, libfreenect's registration formula), and the pinhole camera that
/// back-projects it (section 9: f = reference_distance / (2 x reference_pixel_size)).
///
/// Both tables come from one formula in double precision: z_mm = 10 x (ref_dist + m x ref_dist /
/// (b - m)), m = ((raw - 4 x const_shift) / 4 - 0.375) x ref_pix. Entry 2047 ("no reading"),
/// entries at or past the pole (m >= b) and depths beyond 10 m are 0, never a wrapped integer.
#include <array>
#include <cstdint>
#include <span>

#include "drivers/kinect_protocol.hpp"
#include "kernels/depth_projection.hpp"

namespace orthoflow::drivers::kinect {

inline constexpr std::uint16_t RAW_NO_READING = 2047;
inline constexpr double DEPTH_MAX_MM = 10000.0;  ///< libfreenect's FREENECT_DEPTH_MM_MAX_VALUE

/// @brief Depth in millimetres (double) of raw disparity @p raw; 0 where there is none.
[[nodiscard]] double raw_to_mm(std::uint16_t raw, const Calibration& calibration) noexcept;

/// @brief raw -> whole millimetres (truncated, as libfreenect's DEPTH_MM output).
using DepthTableMm = std::array<std::uint16_t, kernels::DISPARITY_TABLE_SIZE>;
[[nodiscard]] DepthTableMm make_depth_table_mm(const Calibration& calibration) noexcept;

/// @brief raw -> metres (float), the table kernels::depth_to_points reads.
void make_depth_table_m(const Calibration& calibration,
                        std::span<float, kernels::DISPARITY_TABLE_SIZE> table_m) noexcept;

/// @brief The depth camera's pinhole model from the zero plane: fx = fy = ref_dist / (2 ref_pix)
/// (575.8 px for 120 mm and 0.1042 mm), principal point at the image centre (319.5, 239.5).
[[nodiscard]] kernels::DepthCamera depth_camera(const Calibration& calibration) noexcept;

}  // namespace orthoflow::drivers::kinect
