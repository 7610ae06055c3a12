#pragma once
/// @file
/// @brief Per-cluster statistics: point count, centroid, covariance, axis-aligned and oriented
/// boxes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Statistics of one cluster. The oriented box is the PCA frame: axes are the covariance
/// eigenvectors (rows, largest variance first, right-handed), obb_min/max the extents in that frame
/// around obb_center, the centroid.
struct ClusterStats {
  std::size_t points = 0;
  std::array<float, 3> centroid{};
  std::array<float, 6> covariance{};  ///< xx, xy, xz, yy, yz, zz (population, divided by points)
  std::array<float, 3> bbox_min{};
  std::array<float, 3> bbox_max{};
  std::array<float, 9> obb_axes{};  ///< row-major 3x3
  std::array<float, 3> obb_min{};
  std::array<float, 3> obb_max{};
};

/// @brief Double-precision accumulators of one cluster (caller-provided scratch of
/// cluster_stats()).
struct ClusterMoments {
  std::array<double, 3> ref{};  ///< first point: moments are taken around it (precision far from 0)
  std::array<double, 3> sum{};  ///< sum of (p - ref)
  std::array<double, 6> outer{};  ///< sum of (p - ref)(p - ref)^T, upper triangle xx xy xz yy yz zz
};

/// @brief Statistics of the clusters 0..out.size()-1 given per-point @p labels (-1 = none). Three
/// passes (counts and boxes; moments in double; extents in the PCA frame). Clusters with no points
/// stay zero.
/// @pre labels.size() >= points.size(); every label < out.size() <= moments.size(); labelled points
/// finite.
/// @return out.size(). @note Allocation-free, thread-safe, deterministic. No SIMD variant: a
/// label-indexed scatter.
std::size_t cluster_stats(PointsView points, std::span<const std::int32_t> labels,
                          std::span<ClusterMoments> moments, std::span<ClusterStats> out) noexcept;

/// @brief cluster_stats() visiting only the points of @p members (e.g. the pixels a clustering
/// listed, ClusterScratch::listed_members()) instead of scanning every label: bit-identical to
/// cluster_stats() when @p members holds, in ascending order, every index with a label >= 0 (other
/// entries, with label -1, are skipped). @pre as cluster_stats(); every member < labels.size().
/// @return out.size().
/// @note Allocation-free, thread-safe, deterministic.
std::size_t cluster_stats_listed(PointsView points, std::span<const std::int32_t> labels,
                                 std::span<const std::uint32_t> members,
                                 std::span<ClusterMoments> moments,
                                 std::span<ClusterStats> out) noexcept;

}  // namespace orthoflow::kernels
