#pragma once
/// @file
/// @brief Puts an unorganized cloud that a pinhole camera took back on its pixel grid: a Kinect
/// frame stored with its invalid pixels dropped (HEIGHT 1, as ROS bags and many recordings keep
/// them) becomes an organized cloud again, so that it takes the organized chain (strided pixel
/// sample, crowded-scene mode) instead of the voxel grid (docs/SEGMENTATION.md, "Unorganized
/// clouds").
///
/// Method: in the camera frame every point of a pinhole image satisfies x / z = (u - cx) / fx and
/// y / z = (v - cy) / fy with integer pixel (u, v). The column pitch 1 / fx is the median step of
/// x / z between consecutive stored points of one row (same y / z), the row pitch 1 / fy the median
/// step of y / z where a row ends; both are then refined by least squares over every point against
/// its rounded pixel. The grid is accepted only if every point lies within MAX_RESIDUAL_PX of its
/// pixel in both directions and no two points share a pixel; anything else (a cloud moved out of
/// the camera frame, merged from several views, shuffled, voxelised) is refused with the reason,
/// and the caller keeps the unorganized cloud. Deterministic (double arithmetic, no randomness).
#include <cstdint>
#include <string_view>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Largest distance (pixels) a point may lie from its grid pixel.
inline constexpr double MAX_RESIDUAL_PX = 0.2;
/// @brief Largest grid side accepted (pixels).
inline constexpr std::uint32_t MAX_GRID_SIDE = 4096;
/// @brief Fewest finite points a grid is looked for in.
inline constexpr std::size_t MIN_GRID_POINTS = 1000;

/// @brief The pixel grid found: pixel (u, v) of a point, u in [0, width), v in [0, height), is
/// u = fx x / z + cx, v = fy y / z + cy (fx or fy negative when the cloud's rows or columns run
/// backwards).
struct PinholeGrid {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  std::uint32_t width = 0, height = 0;
  double max_residual_px = 0.0;  ///< the farthest point from its pixel
};

/// @brief Why no grid was found.
enum class GridRefusal : std::uint8_t {
  TOO_FEW_POINTS,  ///< fewer than MIN_GRID_POINTS finite points in front of the sensor
  NO_PITCH,        ///< the stored order shows no row of consecutive pixels to measure the pitch on
  OFF_GRID,        ///< a point lies farther than MAX_RESIDUAL_PX from every pixel
  TOO_LARGE,       ///< the grid would be wider or higher than MAX_GRID_SIDE (or the caller's limit)
  SHARED_PIXEL,    ///< two points fall on one pixel
};
[[nodiscard]] std::string_view to_string(GridRefusal refusal) noexcept;

/// @brief Finds the pixel grid of @p cloud's finite points with z > 0 (others are ignored).
[[nodiscard]] Result<PinholeGrid, GridRefusal> find_pinhole_grid(PointsView cloud);

/// @brief @p out = @p in on @p grid: organized, width x height, NaN where no point fell, with
/// in's rgb and label fields and info. @pre grid came from find_pinhole_grid(in.points()).
void regrid(const PointCloud& in, const PinholeGrid& grid, PointCloud& out);

/// @brief find_pinhole_grid + regrid: organizes @p cloud in place when it is unorganized and a
/// grid of at most @p max_points pixels is found (a larger one: TOO_LARGE, the cloud unchanged).
/// @return the grid, or why not (an organized cloud is left alone: its grid).
Result<PinholeGrid, GridRefusal> organize_if_pinhole(
    PointCloud& cloud, std::size_t max_points = std::size_t{MAX_GRID_SIDE} * MAX_GRID_SIDE);

}  // namespace orthoflow::kernels
