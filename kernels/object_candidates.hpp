#pragma once
/// @file
/// @brief The object-candidate constraints of thesis Table 3.1 that need no tracking, on the
/// clusters of the object stage (kernels/tabletop_stages.hpp): C_size (the largest extent between
/// min_size and max_size) and C_edge (the centroid at least edge_margin inside the table polygon);
/// and the gather of the kept candidates' points into one contiguous span each (a counting sort by
/// cluster), carrying an optional per-point tag (a ground-truth label) along. The chain and the
/// graph's objects node call these.
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/cluster_stats.hpp"
#include "kernels/convex_hull.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::kernels {

/// @brief Candidate constraints; defaults are the objects node's.
struct CandidateParams {
  float min_size = 0.02F;     ///< C_size: the largest OBB extent must reach this (m)
  float max_size = 0.5F;      ///< C_size: the largest OBB extent at most this (graspable)
  float edge_margin = 0.02F;  ///< C_edge: centroid at least this far inside the table polygon (m)
};

/// @brief What select_candidates() decided.
struct CandidateCounts {
  std::size_t kept = 0;
  std::size_t rejected_size = 0;
  std::size_t rejected_edge = 0;
  std::size_t over_capacity = 0;  ///< passed both constraints but found slot_of's candidates full
};

/// @brief Signed distance from (u, v) to the nearest edge of the counter-clockwise convex polygon
/// (@p hu, @p hv): positive inside. @return a huge value for a polygon without edges.
[[nodiscard]] double inside_distance(double u, double v, std::span<const double> hu,
                                     std::span<const double> hv) noexcept;

/// @brief Applies C_size and C_edge to @p clusters in order; slot_of[c] = the candidate index of
/// cluster c (0, 1, ... in cluster order) or -1 when rejected. At most @p max_candidates are kept:
/// when more pass, the nearest to the sensor (centroid range; ties: cluster order), so a crowded
/// frame drops its farthest objects (kernels::ObjectBudget step 3).
/// @pre slot_of.size() >= clusters.size(); hu/hv in make_plane_basis(plane). Allocation-free,
/// deterministic.
CandidateCounts select_candidates(std::span<const ClusterStats> clusters, const Plane& plane,
                                  std::span<const double> hu, std::span<const double> hv,
                                  const CandidateParams& params, std::size_t max_candidates,
                                  std::span<std::int32_t> slot_of) noexcept;

/// @brief Where each candidate's points go: first[k], count[k] (count filled by
/// gather_candidates()).
struct CandidateSpan {
  std::uint32_t first = 0;
  std::uint32_t count = 0;
};

/// @brief Counting sort of the candidates' points: candidate k's points land in dst[first, first +
/// n_k) with first the sum of the earlier candidates' sizes (@p sizes, from their
/// ClusterStats::points), in ascending point order. With @p tags non-empty (a per-point tag such as
/// a ground-truth label), row k of
/// @p tag_histogram (@p bins entries per candidate, zeroed here) counts the tags < bins of
/// candidate k's points. @p members as ObjectClusters::members (empty: every index).
/// @pre dst holds sum(sizes); spans.size() >= sizes.size(); tag_histogram.size() >= sizes.size() *
/// bins when tags are given. @return the points written. Allocation-free, deterministic.
std::size_t gather_candidates(PointsView target, std::span<const std::int32_t> labels,
                              std::span<const std::uint32_t> members,
                              std::span<const std::int32_t> slot_of,
                              std::span<const std::size_t> sizes, PointsSpan dst,
                              std::span<CandidateSpan> spans,
                              std::span<const std::uint32_t> tags = {}, std::size_t bins = 0,
                              std::span<std::uint32_t> tag_histogram = {}) noexcept;

/// @brief The tag 1..bins-1 of a histogram row (gather_candidates) held by at least half of @p
/// points, or 0 (tag 0 never counts). Allocation-free.
[[nodiscard]] std::uint32_t majority_tag(std::span<const std::uint32_t> histogram,
                                         std::size_t points) noexcept;

}  // namespace orthoflow::kernels
