#pragma once
/// @file
/// @brief Is the plane the table stage found a table? (docs/SEGMENTATION.md, "The table verdict").
/// The stage always returns its best plane; a wall, a person's back or a desk's side is a plane
/// too. A plane is a table only if it is level within max_tilt_deg of "up" (when the frame knows
/// where up is: the Kinect's accelerometer, a simulated camera's pose, or a configured camera
/// pose), lies below the camera within the configured height range, and holds a minimum share of
/// the plane input and a minimum support area. Without "up" the level test is skipped and the
/// others still apply. Pure, allocation-free.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "kernels/ransac_plane.hpp"

namespace orthoflow::kernels {

/// @brief The verdict's thresholds. Defaults: docs/SEGMENTATION.md (chosen on the 45 mOSD learn
/// frames and the synthetic scenes, with a wide margin).
struct TableVerdictParams {
  float max_tilt_deg = 10.0F;  ///< plane normal within this of "up"
  float min_height_m = 0.1F;   ///< camera at least this far from the plane...
  float max_height_m = 2.5F;   ///< ... and at most this far
  float min_share = 0.2F;      ///< plane inliers / dense plane-input points
  float min_area_m2 = 0.1F;    ///< support polygon area
};

/// @brief The verdict. ACCEPTED and HELD are tables; the rest say why a frame has none.
enum class TableReason : std::uint8_t {
  ACCEPTED,      ///< this frame's plane passed every test
  HELD,          ///< this frame's plane failed, the last accepted table is kept (hysteresis)
  NO_PLANE,      ///< the table stage found no plane
  NOT_LEVEL,     ///< more than max_tilt_deg from level
  OUT_OF_RANGE,  ///< nearer or farther from the camera than the height range
  TOO_SMALL,     ///< too small a share of the plane input or too small an area
};

/// @brief "accepted", "held", "no_plane", "not_level", "out_of_range", "too_small".
[[nodiscard]] std::string_view table_reason_name(TableReason reason) noexcept;

/// @brief What the verdict measured. tilt_deg is NaN without "up".
struct TableJudgement {
  TableReason reason = TableReason::NO_PLANE;
  float tilt_deg = 0.0F;
  float height_m = 0.0F;
  float share = 0.0F;
  float area_m2 = 0.0F;
};

/// @brief Judges @p plane (normal facing the sensor, d >= 0: the table stage's convention) with
/// @p inliers of @p sample plane-input points and the support polygon @p hull_u / @p hull_v (m).
/// @param up unit "up" in the sensor frame, or null when nothing gives it. Tests run in the order
/// of TableReason; the first failing one is the reason.
[[nodiscard]] TableJudgement judge_table(const Plane& plane, std::size_t inliers,
                                         std::size_t sample, std::span<const double> hull_u,
                                         std::span<const double> hull_v,
                                         const std::array<float, 3>* up,
                                         const TableVerdictParams& params) noexcept;

/// @brief Area of a simple polygon (shoelace), m^2; 0 for fewer than 3 vertices.
[[nodiscard]] double polygon_area(std::span<const double> u, std::span<const double> v) noexcept;

}  // namespace orthoflow::kernels
