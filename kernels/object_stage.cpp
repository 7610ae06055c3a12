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
constexpr std::uint32_t MAX_STRIDE = 4;  // budget step 1 thins the prism to at most 1 in 16

/// Budget step 1: the smallest stride s (1..MAX_STRIDE) whose s x s thinning of @p inside prism
/// pixels fits @p max_points (0: no limit).
std::uint32_t stride_for(std::size_t inside, std::size_t max_points) noexcept {
  std::uint32_t s = 1;
  while (max_points > 0 && s < MAX_STRIDE && inside > max_points * s * s) ++s;
  return s;
}

/// Keeps the prism pixels on every s-th row and column. @return the pixels kept.
std::size_t thin_mask(std::span<std::uint8_t> mask, std::size_t w, std::uint32_t s) noexcept {
  std::size_t kept = 0;
  for (std::size_t r = 0, ri = 0; r * w < mask.size(); ++r, ri = ri + 1 == s ? 0 : ri + 1) {
    const auto row = mask.subspan(r * w, std::min(w, mask.size() - r * w));
    if (ri != 0) {  // not a grid row: nothing on it is clustered
      std::fill(row.begin(), row.end(), std::uint8_t{0});
      continue;
    }
    for (std::size_t c = 0, ci = 0; c < row.size(); ++c, ci = ci + 1 == s ? 0 : ci + 1) {
      row[c] = ci == 0 ? row[c] : std::uint8_t{0};
      kept += row[c];
    }
  }
  return kept;
}

/// Labels each prism pixel the thinning left out from the nearest labelled corner of its s x s
/// cell (the pixels clustered) within @p tol metres, or -1.
void fill_thinned(PointsView p, std::size_t w, std::uint32_t s, std::span<const std::uint8_t> prism,
                  std::span<std::int32_t> labels, float tol) noexcept {
  const std::size_t h = prism.size() / w;
  for (std::size_t r = 0, r0 = 0; r < h; ++r) {
    if (r - r0 == s) r0 = r;
    const auto row = prism.subspan(r * w, w);
    auto it = std::find(row.begin(), row.end(), std::uint8_t{1});
    if (it == row.end()) continue;  // most rows hold no prism pixel
    for (std::size_t c = 0, c0 = 0; c < w; ++c) {
      if (c - c0 == s) c0 = c;
      const std::size_t i = r * w + c;
      if (row[c] == 0 || (r == r0 && c == c0)) continue;
      float best = tol * tol;
      std::int32_t label = -1;
      for (const std::size_t rr : {r0, r0 + s}) {
        for (const std::size_t cc : {c0, c0 + s}) {
          if (rr >= h || cc >= w) continue;
          const std::size_t j = rr * w + cc;
          if (labels[j] < 0) continue;
          const float dx = p.x[j] - p.x[i], dy = p.y[j] - p.y[i], dz = p.z[j] - p.z[i];
          const float d2 = dx * dx + dy * dy + dz * dz;
          if (d2 < best) best = d2, label = labels[j];
        }
      }
      labels[i] = label;
    }
  }
}

/// The parameters a thinned frame is clustered with: the same metric neighbourhood (the window
/// scales with the stride) and cluster sizes in points scaled by the share of pixels kept.
SegmentationParams strided(const SegmentationParams& p, std::uint32_t s) noexcept {
  SegmentationParams q = p;
  const std::uint32_t area = s * s;
  q.cluster.pixel_radius = p.cluster.pixel_radius * s;
  q.cluster.pixel_step = s;
  q.cluster.min_size = std::max<std::uint32_t>(1, (p.cluster.min_size + area - 1) / area);
  q.cluster.max_size = std::max(q.cluster.min_size, p.cluster.max_size / area);
  return q;
}

}  // namespace

ObjectStage::ObjectStage(std::size_t max_points, std::uint32_t min_cluster_size)
    : heights_(max_points),
      mask_(max_points),
      prism_mask_(max_points),
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

Result<ObjectClusters, SegmentationError> ObjectStage::run(
    CloudView cloud, const PlaneInput& plane_input, const TableModel& table,
    const SegmentationParams& given) noexcept {
  using C = SegmentationError::Code;
  auto start = Clock::now();
  const bool organized = takes_organized_path(cloud, given);
  // The prism runs on the full-resolution pixels (organized) or on the plane's input points; the
  // ROI applies to the pixels too (the plane input lies in it already).
  const PointsView target = organized ? cloud.points : plane_input.dense;
  if (target.size() > labels_.size())
    return err(fail(C::CLOUD_TOO_LARGE, 0, static_cast<double>(target.size())));
  const PlaneBasis basis = make_plane_basis(table.plane.plane);
  const Prism prism{table.plane.plane, basis,       table.hull_u, table.hull_v,
                    given.h_min,       given.h_max, given.roi};
  const std::size_t in_prism = polygonal_prism(target, prism, heights_, mask_);
  const std::uint32_t stride = organized ? stride_for(in_prism, given.budget.max_points) : 1;
  if (stride > 1) std::copy_n(mask_.begin(), target.size(), prism_mask_.begin());
  const std::size_t inside =
      stride > 1 ? thin_mask(std::span(mask_).first(target.size()), cloud.width, stride) : in_prism;
  const SegmentationParams p = stride > 1 ? strided(given, stride) : given;
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
  const bool refine = p.budget.max_refine_clusters == 0 || clusters <= p.budget.max_refine_clusters;
  if (refine && p.merge_overlap > 0.0F)
    clusters = merge_footprints(target, members, basis, clusters, p.merge_overlap,
                                crowded ? p.crease.max_rise : -1.0F, p.crease.stand_height,
                                p.cluster.tolerance);
  std::fill_n(joined_.begin(), std::min(clusters, joined_.size()), std::uint8_t{0});
  if (refine && crowded && p.crease.occlusion_rows > 0)
    clusters = join_occluded({target, cloud.width, cloud.height}, members, clusters, p.crease);
  if (refine && crowded)
    clusters = split_necks(target, members, basis, clusters, p.cluster.min_size, p.crease);
  const auto stats = std::span(stats_).first(clusters);
  if (organized) {
    cluster_stats_listed(target, labels, members, moments_, stats);
  } else {
    cluster_stats(target, labels, moments_, stats);
  }
  if (stride > 1) {
    fill_thinned(target, cloud.width, stride,
                 std::span<const std::uint8_t>(prism_mask_).first(target.size()), labels,
                 p.cluster.tolerance);
  }
  return ObjectClusters{target,   labels,          members, stats, in_prism,
                        prism_ms, ms_since(start), stride,  refine};
}

}  // namespace orthoflow::kernels
