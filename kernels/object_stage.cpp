// Stage 3 of the tabletop chain (kernels/tabletop_stages.hpp): ObjectStage's scratch and its run,
// the prism over the table, then the clusters (Euclidean or the crowded mode), the footprint merge,
// the occlusion join, the neck split and the statistics. The steps after the clustering are in
// footprint_merge.cpp, crease_split.cpp, occlusion_join.cpp and neck_split.cpp.
#include <algorithm>

#include "kernels/detail/stage_common.hpp"
#include "kernels/polygonal_prism.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels {

namespace {

using detail::Clock;
using detail::fail;
using detail::ms_since;

constexpr std::size_t MAX_MERGE =
    256;  // clusters beyond this are not merged (a cluttered frame; O(n^2) pairs)

}  // namespace

ObjectStage::ObjectStage(std::size_t max_points, std::uint32_t min_cluster_size)
    : heights_(max_points),
      mask_(max_points),
      labels_(max_points),
      // every cluster has at least max(1, min_size) points, which bounds the cluster count
      moments_(max_points / std::max<std::size_t>(1, min_cluster_size) + 1),
      stats_(moments_.size()),
      cluster_scratch_(max_points),
      footprints_(std::min(MAX_MERGE, moments_.size())),
      root_(footprints_.size()),
      new_id_(footprints_.size()),
      nx_(max_points),
      ny_(max_points),
      nz_(max_points),
      off_crease_(max_points),
      round_(max_points),
      members_(max_points),
      pending_(max_points),
      votes_(MAX_OCCLUSION_PIECES * MAX_OCCLUSION_PIECES),
      pieces_(MAX_OCCLUSION_PIECES),
      joined_(root_.size()),
      neck_(max_points) {}

Result<ObjectClusters, SegmentationError> ObjectStage::run(CloudView cloud,
                                                           const PlaneInput& plane_input,
                                                           const TableModel& table,
                                                           const SegmentationParams& p) noexcept {
  using C = SegmentationError::Code;
  auto start = Clock::now();
  const bool organized = takes_organized_path(cloud, p);
  // The prism runs on the full-resolution pixels (organized) or on the plane's input points; the
  // ROI applies to the pixels too (the plane input lies in it already).
  const PointsView target = organized ? cloud.points : plane_input.dense;
  if (target.size() > labels_.size())
    return err(fail(C::CLOUD_TOO_LARGE, 0, static_cast<double>(target.size())));
  const PlaneBasis basis = make_plane_basis(table.plane.plane);
  const Prism prism{table.plane.plane, basis, table.hull_u, table.hull_v, p.h_min, p.h_max, p.roi};
  const std::size_t inside = polygonal_prism(target, prism, heights_, mask_);
  const double prism_ms = ms_since(start);
  const auto mask = std::span<const std::uint8_t>(mask_).first(target.size());
  const auto labels = std::span(labels_).first(target.size());
  const bool crowded = organized && p.cluster_mode == ClusterMode::CROWDED;
  auto clusters_result =
      crowded     ? cluster_crowded({target, cloud.width, cloud.height}, p)
      : organized ? euclidean_cluster_organized({target, cloud.width, cloud.height}, mask,
                                                p.cluster, cluster_scratch_, labels)
                  : euclidean_cluster(target, mask, p.cluster, cluster_scratch_, labels);
  if (!clusters_result) {
    const auto& e = clusters_result.error();
    return err(fail(C::CLUSTERING_FAILED, static_cast<std::uint8_t>(e.code), e.value));
  }
  // Organized: only the pixels the clustering listed (the prism's), not a scan of the whole label
  // frame.
  const auto members = crowded     ? std::span<const std::uint32_t>(members_).first(inside)
                       : organized ? cluster_scratch_.listed_members()
                                   : std::span<const std::uint32_t>{};
  std::size_t clusters = std::min(*clusters_result, stats_.size());
  if (p.merge_overlap > 0.0F)
    clusters = merge_footprints(target, members, basis, clusters, p.merge_overlap,
                                crowded ? p.crease.max_rise : -1.0F, p.crease.stand_height,
                                p.cluster.tolerance);
  std::fill_n(joined_.begin(), std::min(clusters, joined_.size()), std::uint8_t{0});
  if (crowded && p.crease.occlusion_rows > 0)
    clusters = join_occluded({target, cloud.width, cloud.height}, members, clusters, p.crease);
  if (crowded)
    clusters = split_necks(target, members, basis, clusters, p.cluster.min_size, p.crease);
  const auto stats = std::span(stats_).first(clusters);
  if (organized) {
    cluster_stats_listed(target, labels, members, moments_, stats);
  } else {
    cluster_stats(target, labels, moments_, stats);
  }
  return ObjectClusters{target, labels, members, stats, inside, prism_ms, ms_since(start)};
}

}  // namespace orthoflow::kernels
