#pragma once
/// @file
/// @brief Raw Kinect v1 disparity to metric depth from the device's own calibration
/// (specs/KINECT_V1.md 8.2, libfreenect's registration formula), its inverse, and the pinhole
/// camera that back-projects it (section 9: f = reference_distance / (2 x reference_pixel_size)).
///
/// One formula, in double precision, serves every table here and the simulator
/// (simulation/world/kinect_depth_model.hpp): z_mm = 10 x (ref_dist + m x ref_dist / (b - m)),
/// m = ((raw - 4 x const_shift) / 4 - 0.375) x ref_pix. Entry 2047 ("no reading"), entries at or
/// past the pole (m >= b) and, in the tables, depths beyond 10 m are 0, never a wrapped integer.
/// Its inverse (mm_to_disparity, mm_to_raw) is what a simulated device sends for a depth.
/// All functions are pure: thread-safe, no allocation, deterministic.
#include <array>
#include <cstdint>
#include <span>

#include "drivers/kinect/kinect_protocol.hpp"
#include "kernels/depth_projection.hpp"

namespace orthoflow::drivers::kinect {

inline constexpr std::uint16_t RAW_NO_READING = 2047;
inline constexpr double DEPTH_MAX_MM = 10000.0;  ///< libfreenect's FREENECT_DEPTH_MM_MAX_VALUE

/// @brief The four numbers of the registration formula in double precision: a device's
/// Calibration (disparity_model(), exact), or a simulator's own values. Plain data; the defaults
/// are the brief's typical device (KINECT_V1.md 8.1).
struct DisparityModel {
  double const_shift = 200.0;               ///< zero-plane shift (algorithm parameter 0x00)
  double reference_distance_mm = 120.0;     ///< zero-plane reference distance
  double reference_pixel_size_mm = 0.1042;  ///< zero-plane reference pixel size
  double emitter_dist_cm = 7.5;             ///< dcmos_emitter_dist: the projector-camera baseline
};

/// @brief The formula's numbers of @p calibration (float to double: exact). @pre none.
[[nodiscard]] DisparityModel disparity_model(const Calibration& calibration) noexcept;

/// @brief Depth in millimetres of a continuous raw disparity @p raw; 0 for raw >= 2047 and at or
/// past the pole. No 10 m cut. @pre none.
[[nodiscard]] double disparity_to_mm(double raw, const DisparityModel& model) noexcept;
/// @brief The continuous raw disparity whose depth is @p mm (inverse of disparity_to_mm).
/// @pre mm > 0 (else the result is meaningless).
[[nodiscard]] double mm_to_disparity(double mm, const DisparityModel& model) noexcept;
/// @brief The 11-bit raw value a device sends for depth @p mm: the nearest disparity, clamped to
/// 0..2046; RAW_NO_READING for a depth that is not finite or not > 0. @pre none.
/// @note Round trip: raw_to_mm of the result lies within one disparity step of @p mm (in range).
[[nodiscard]] std::uint16_t mm_to_raw(double mm, const DisparityModel& model) noexcept;

/// @brief Depth in millimetres (double) of raw disparity @p raw; 0 where there is none or beyond
/// DEPTH_MAX_MM. @pre none.
[[nodiscard]] double raw_to_mm(std::uint16_t raw, const Calibration& calibration) noexcept;

/// @brief raw -> whole millimetres (truncated, as libfreenect's DEPTH_MM output).
using DepthTableMm = std::array<std::uint16_t, kernels::DISPARITY_TABLE_SIZE>;
/// @brief The DEPTH_MM table of @p calibration. @pre none.
[[nodiscard]] DepthTableMm make_depth_table_mm(const Calibration& calibration) noexcept;

/// @brief raw -> metres (float), the table kernels::depth_to_points reads. @pre none.
void make_depth_table_m(const Calibration& calibration,
                        std::span<float, kernels::DISPARITY_TABLE_SIZE> table_m) noexcept;
/// @brief The same table from the formula's numbers (the simulator's depth table). @pre none.
void make_depth_table_m(const DisparityModel& model,
                        std::span<float, kernels::DISPARITY_TABLE_SIZE> table_m) noexcept;

/// @brief The depth camera's pinhole model from the zero plane: fx = fy = ref_dist / (2 ref_pix)
/// (575.8 px for 120 mm and 0.1042 mm), principal point at the image centre (319.5, 239.5).
/// @pre none.
[[nodiscard]] kernels::DepthCamera depth_camera(const Calibration& calibration) noexcept;

}  // namespace orthoflow::drivers::kinect
