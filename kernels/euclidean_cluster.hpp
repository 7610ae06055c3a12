#pragma once
/// @file
/// @brief Euclidean clustering (specs/PIPELINE.md section 4): connected components of the points
/// under a distance tolerance, with union-find. Organized clouds use the image-space neighbourhood
/// (a (2r+1)-pixel window), unorganized ones a sorted spatial grid of tolerance-sized cells; no k-d
/// tree.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Clustering settings (PCL EuclideanClusterExtraction: ClusterTolerance,
/// Min/MaxClusterSize).
struct ClusterParams {
  float tolerance = 0.02F;      ///< metres
  std::uint32_t min_size = 50;  ///< smaller components get label -1
  std::uint32_t max_size =
      std::numeric_limits<std::uint32_t>::max();  ///< larger components get label -1
  std::uint32_t pixel_radius =
      2;  ///< organized only: neighbours within this many pixels (Chebyshev)
  /// Organized only: the mask holds pixels on every pixel_step-th row and column only (the object
  /// stage's budget thinned it; pixel_radius a multiple of it), so the window visits those alone.
  /// The partition is the one pixel_step 1 gives on the same mask.
  std::uint32_t pixel_step = 1;
};

/// @brief Why clustering refused to run.
struct ClusterError {
  enum class Code : std::uint8_t {
    BAD_PARAMS,         ///< tolerance not finite or <= 0, min_size > max_size, pixel_radius 0,
                        ///< pixel_step 0 or not dividing pixel_radius
    SCRATCH_TOO_SMALL,  ///< scratch capacity below the point count
    GRID_OVERFLOW,      ///< extent / tolerance needs more than 64 bits of cell key
  };
  Code code = Code::BAD_PARAMS;
  double value = 0.0;
  [[nodiscard]] std::string to_string() const;
};

/// @brief Working memory sized once for max_points (about 40 bytes per point).
/// @note Allocates only in the constructor; one clustering at a time per scratch.
struct ClusterScratch {
  explicit ClusterScratch(std::size_t max_points)
      : parent(max_points),
        count(max_points),
        keys(max_points),
        keys_tmp(max_points),
        order(max_points),
        order_tmp(max_points),
        cell_start(max_points + 1) {}
  std::vector<std::uint32_t> parent, count;
  std::vector<std::uint64_t> keys, keys_tmp;
  std::vector<std::uint32_t> order, order_tmp, cell_start;
  std::size_t listed =
      0;  ///< after euclidean_cluster_organized: order[0, listed) = its included pixels, ascending
  [[nodiscard]] std::size_t capacity() const noexcept { return parent.size(); }
  /// @brief The included pixels of the last euclidean_cluster_organized() (a superset of the
  /// labelled ones, ascending: cluster_stats_listed()'s members); empty after euclidean_cluster().
  [[nodiscard]] std::span<const std::uint32_t> listed_members() const noexcept {
    return std::span<const std::uint32_t>(order).first(listed);
  }
};

/// @brief Clusters the finite points i with mask[i] != 0 (all finite points when @p mask is empty)
/// of an organized cloud: two points are linked when they are within the pixel window and within
/// tolerance in 3-D. labels[i] = cluster id or -1 (masked out, NaN, or a component outside the size
/// range). Ids are 0, 1, ... in order of each cluster's lowest point index: deterministic.
/// @pre cloud.points.size() == width * height <= labels.size(). @return the cluster count.
[[nodiscard]] Result<std::size_t, ClusterError> euclidean_cluster_organized(
    CloudView cloud, std::span<const std::uint8_t> mask, const ClusterParams& params,
    ClusterScratch& scratch, std::span<std::int32_t> labels) noexcept;

/// @brief The same for any cloud, with a spatial grid: two points are linked when within tolerance.
/// The partition equals PCL's EuclideanClusterExtraction (connected components of the same graph).
[[nodiscard]] Result<std::size_t, ClusterError> euclidean_cluster(
    PointsView points, std::span<const std::uint8_t> mask, const ClusterParams& params,
    ClusterScratch& scratch, std::span<std::int32_t> labels) noexcept;

}  // namespace orthoflow::kernels
