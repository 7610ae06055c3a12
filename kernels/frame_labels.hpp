#pragma once
/// @file
/// @brief Per-point labels of one segmented organized frame, in the convention `orthoflow segment
/// --labels-out`, `orthoflow run --labels-out` and `orthoflow evaluate-segmentation` share:
/// 0 = no object, 1 = table, k + 2 = object (candidate) k.
#include <cstdint>
#include <span>

#include "kernels/crop.hpp"
#include "kernels/plane_distance.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Label of a table point; objects start at FIRST_OBJECT_LABEL.
inline constexpr std::uint32_t TABLE_LABEL = 1;
inline constexpr std::uint32_t FIRST_OBJECT_LABEL = 2;

/// @brief out[i]: FIRST_OBJECT_LABEL + slot_of[cluster_of[i]] when point i is in a cluster that
/// is a candidate; otherwise TABLE_LABEL when it is finite, inside @p roi and within @p table_tau
/// of @p plane; otherwise 0. @p cluster_of: per point, a cluster id or -1 (SegmentationResult::
/// labels of the organized chain); @p slot_of: per cluster, its candidate index or -1.
/// @pre out.size() == cluster_of.size() == points.size(). Allocation-free, deterministic.
void frame_labels(PointsView points, const Plane& plane, float table_tau, const AxisBox& roi,
                  std::span<const std::int32_t> cluster_of, std::span<const std::int32_t> slot_of,
                  std::span<std::uint32_t> out) noexcept;

}  // namespace orthoflow::kernels
