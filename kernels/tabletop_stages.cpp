#include "kernels/tabletop_stages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "kernels/cloud_stats.hpp"
#include "kernels/pixel_subsample.hpp"
#include "kernels/polygonal_prism.hpp"

namespace orthoflow::kernels {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point& start) noexcept {
  const auto now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  start = now;
  return ms;
}

constexpr std::size_t MAX_MERGE =
    256;  // clusters beyond this are not merged (a cluttered frame; O(n^2) pairs)

/// Indices of the points within tau of the plane (ransac_plane's rule), ascending. @pre out holds
/// them all.
std::size_t collect_inliers(PointsView p, const Plane& plane, float tau,
                            std::span<std::uint32_t> out) noexcept {
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const float dist =
        plane.normal[0] * p.x[i] + plane.normal[1] * p.y[i] + plane.normal[2] * p.z[i] + plane.d;
    out[n] = static_cast<std::uint32_t>(i);
    n += std::fabs(dist) <= tau ? 1U : 0U;  // false for NaN
  }
  return n;
}

PointsView first(PointsSpan s, std::size_t offset, std::size_t n) noexcept {
  return PointsView{s.x.subspan(offset, n), s.y.subspan(offset, n), s.z.subspan(offset, n)};
}

std::size_t cells(std::uint32_t extent, std::uint32_t stride) noexcept {
  return (extent + stride - 1) / stride;
}

SegmentationError fail(SegmentationError::Code code, std::uint8_t cause = 0,
                       double value = 0.0) noexcept {
  return SegmentationError{code, cause, value, 0, 0};
}

constexpr std::size_t MIN_PLANE_POINTS = 3;  // RANSAC's minimum

/// FEW_POINTS_IN_ROI with the cloud's finite points: says whether the points are missing or
/// outside the ROI. Only on the failure path (a pass over the cloud).
SegmentationError few_points_in_roi(PointsView points, const AxisBox& roi,
                                    std::size_t inside) noexcept {
  SegmentationError e =
      fail(SegmentationError::Code::FEW_POINTS_IN_ROI, 0, static_cast<double>(inside));
  e.finite = cloud_stats(points).finite;
  e.roi = roi;
  return e;
}

}  // namespace

bool takes_organized_path(CloudView cloud, const SegmentationParams& params) noexcept {
  return params.use_organized && cloud.organized();
}

bool takes_strided_sample(CloudView cloud, const SegmentationParams& params) noexcept {
  const std::uint32_t s = params.organized_stride;
  return takes_organized_path(cloud, params) && s > 0 &&
         sample_lines(cloud.width, s) >= MIN_SAMPLE_LINES &&
         sample_lines(cloud.height, s) >= MIN_SAMPLE_LINES;
}

PlaneInputStage::PlaneInputStage(std::size_t max_points)
    : max_points_(max_points),
      mask_(max_points),
      kx_(max_points),
      ky_(max_points),
      kz_(max_points),
      voxel_scratch_(max_points) {}

Result<PlaneInput, SegmentationError> PlaneInputStage::run(CloudView cloud,
                                                           const SegmentationParams& p,
                                                           PointsSpan out) noexcept {
  using C = SegmentationError::Code;
  auto start = Clock::now();
  const std::size_t n = cloud.points.size();
  if (n > max_points_) return err(fail(C::CLOUD_TOO_LARGE, 0, static_cast<double>(n)));
  if (takes_organized_path(cloud, p) && n != std::size_t{cloud.width} * cloud.height) {
    SegmentationError e = fail(C::NOT_WIDTH_X_HEIGHT, 0, static_cast<double>(n));
    e.width = cloud.width;
    e.height = cloud.height;
    return err(e);
  }
  if (!takes_strided_sample(cloud, p)) return every_kept_point(cloud, p, out);
  // The plane and hull need a sample about as dense as 5 mm voxels, not a voxel grid over every
  // kept pixel: a strided pixel sample costs 1/stride^2 of the frame and needs no sort. RANSAC
  // scores its hypotheses on the sample at twice the stride (a quarter of the points), written
  // after the dense one.
  const std::uint32_t s = p.organized_stride;
  const std::size_t dense_max = cells(cloud.width, s) * cells(cloud.height, s);
  const std::size_t sparse_max = cells(cloud.width, 2 * s) * cells(cloud.height, 2 * s);
  if (out.size() < dense_max) {
    return err(fail(C::OUTPUT_TOO_SMALL, 0, static_cast<double>(dense_max)));
  }
  const std::size_t dense = pixel_subsample(cloud, s, p.roi, out);
  // Too few sampled pixels for a plane (a frame with little inside the ROI): every kept pixel may
  // still hold enough, as for an unorganized cloud.
  if (dense < MIN_PLANE_POINTS && out.size() >= n) return every_kept_point(cloud, p, out);
  // No room for the scoring sample after the dense one (stride 1 on a full frame): RANSAC then
  // scores on the dense sample itself, as for small frames.
  const PointsSpan rest{out.x.subspan(dense), out.y.subspan(dense), out.z.subspan(dense)};
  const std::size_t sparse =
      out.size() >= dense_max + sparse_max ? pixel_subsample(cloud, 2 * s, p.roi, rest) : 0;
  return PlaneInput{first(out, 0, dense), first(out, dense, sparse), dense, ms_since(start), 0.0};
}

/// The unorganized path (and the organized one without a strided sample): ROI crop, then the voxel
/// grid, or every kept point when leaf == 0.
Result<PlaneInput, SegmentationError> PlaneInputStage::every_kept_point(CloudView cloud,
                                                                        const SegmentationParams& p,
                                                                        PointsSpan out) noexcept {
  using C = SegmentationError::Code;
  auto start = Clock::now();
  const std::size_t n = cloud.points.size();
  if (out.size() < n) return err(fail(C::OUTPUT_TOO_SMALL, 0, static_cast<double>(n)));
  const std::size_t kept = crop_box_mask(cloud.points, p.roi, mask_);  // NaN points never pass
  if (kept < MIN_PLANE_POINTS) return err(few_points_in_roi(cloud.points, p.roi, kept));
  if (p.leaf == 0.0F) {
    compact_masked(cloud.points, mask_,
                   PointsSpan{out.x.first(kept), out.y.first(kept), out.z.first(kept)}, {});
    return PlaneInput{first(out, 0, kept), {}, kept, ms_since(start), 0.0};
  }
  const PointsSpan kept_span{std::span(kx_).first(kept), std::span(ky_).first(kept),
                             std::span(kz_).first(kept)};
  compact_masked(cloud.points, mask_, kept_span, {});
  const double filter_ms = ms_since(start);
  auto voxel_result = voxel_grid(kept_span, p.leaf, voxel_scratch_, out);
  if (!voxel_result) {
    const auto& e = voxel_result.error();
    return err(fail(C::VOXEL_GRID_FAILED, static_cast<std::uint8_t>(e.code), e.value));
  }
  return PlaneInput{first(out, 0, *voxel_result), {}, kept, filter_ms, ms_since(start)};
}

TableStage::TableStage(std::size_t max_points)
    : inliers_(max_points),
      hull_scratch_(max_points),
      hull_idx_(max_points + 1),
      pu_(max_points),
      pv_(max_points),
      ox_(max_points),
      oy_(max_points),
      oz_(max_points) {}

std::size_t TableStage::refine(PointsView dense, float tau, Plane& plane) noexcept {
  for (const float t : {tau, 0.5F * tau, 0.25F * tau}) {
    const std::size_t found = collect_inliers(dense, plane, t, inliers_);
    if (found < 3) break;
    plane = fit_plane(dense, std::span<const std::uint32_t>(inliers_).first(found));
  }
  return collect_inliers(dense, plane, tau, inliers_);
}

bool TableStage::other_level(PointsView dense, const SegmentationParams& p,
                             RansacPlane& plane) noexcept {
  // The dense sample's points off the plane (farther than 2 tau), then the dominant plane among
  // them.
  std::size_t m = 0;
  const auto& n = plane.plane.normal;
  for (std::size_t i = 0; i < dense.size(); ++i) {
    const float h = n[0] * dense.x[i] + n[1] * dense.y[i] + n[2] * dense.z[i] + plane.plane.d;
    if (!(std::fabs(h) > 2.0F * p.ransac.tau)) continue;  // near the plane, or NaN
    ox_[m] = dense.x[i], oy_[m] = dense.y[i], oz_[m] = dense.z[i];
    ++m;
  }
  if (m < MIN_SPARSE_POINTS || 5 * m < plane.inliers) return false;  // too little for a level
  const PointsView off{std::span<const float>(ox_).first(m), std::span<const float>(oy_).first(m),
                       std::span<const float>(oz_).first(m)};
  auto second = ransac_plane(off, p.ransac, std::span(inliers_).first(m));
  if (!second) return false;
  const auto& n2 = second->plane.normal;
  const float cos = n[0] * n2[0] + n[1] * n2[1] + n[2] * n2[2];
  if (!(cos > 0.985F) || 5 * second->inliers < plane.inliers) return false;  // not a big level
  // Both normals face the sensor (d >= 0), so the level's height above the plane is d - d2.
  const float above = plane.plane.d - second->plane.d;
  const bool plane_was_floor = above > p.h_max;
  const bool plane_was_top = above < 0.0F && -above <= p.h_max;
  if (!plane_was_floor && !plane_was_top) return false;
  plane.plane = second->plane;
  plane.iterations += second->iterations;
  return true;
}

Result<TableModel, SegmentationError> TableStage::run(const PlaneInput& input,
                                                      const SegmentationParams& p,
                                                      std::span<double> hull_u,
                                                      std::span<double> hull_v) noexcept {
  using C = SegmentationError::Code;
  const PointsView dense = input.dense;
  if (dense.size() > inliers_.size())
    return err(fail(C::CLOUD_TOO_LARGE, 0, static_cast<double>(dense.size())));
  const bool two_level = input.sparse.size() >= MIN_SPARSE_POINTS;
  auto ransac_result = ransac_plane(two_level ? input.sparse : dense, p.ransac, inliers_);
  if (!ransac_result) {
    const auto& e = ransac_result.error();
    return err(fail(C::NO_PLANE, static_cast<std::uint8_t>(e.code), e.value));
  }
  RansacPlane plane = *ransac_result;
  // The refit on the dense sample, at tau and then tighter: a hypothesis that RANSAC tilted to take
  // in the foot of an object settles on the table's own points. Then the other-level check.
  PlaneCheck check;
  const std::size_t found = collect_inliers(dense, plane.plane, p.ransac.tau, inliers_);
  if (found < 3) return err(fail(C::FEW_SAMPLE_INLIERS, 0, static_cast<double>(found)));
  plane.inliers = refine(dense, p.ransac.tau, plane.plane);
  if (other_level(dense, p, plane)) {  // (which used inliers_ as scratch)
    check.switched = true;
    plane.inliers = refine(dense, p.ransac.tau, plane.plane);
  } else {
    plane.inliers = collect_inliers(dense, plane.plane, p.ransac.tau, inliers_);
  }
  if (plane.inliers < 3) {
    return err(fail(C::FEW_SAMPLE_INLIERS, 0, static_cast<double>(plane.inliers)));
  }
  {
    double sum_sq = 0.0;
    std::size_t near = 0;
    const auto& n = plane.plane.normal;
    for (std::size_t k = 0; k < plane.inliers; ++k) {
      const std::uint32_t i = inliers_[k];
      const float h = n[0] * dense.x[i] + n[1] * dense.y[i] + n[2] * dense.z[i] + plane.plane.d;
      if (std::fabs(h) > 0.01F) continue;
      ++near;
      sum_sq += double(h) * h;
    }
    check.near_share = float(double(near) / double(plane.inliers));
    check.rms_m = near == 0 ? 0.0F : float(std::sqrt(sum_sq / double(near)));
  }
  const PlaneBasis basis = make_plane_basis(plane.plane);
  const auto idx = std::span<const std::uint32_t>(inliers_).first(plane.inliers);
  project_to_plane(dense, idx, basis, pu_, pv_);
  const std::size_t h =
      convex_hull_2d(std::span<const double>(pu_).first(idx.size()),
                     std::span<const double>(pv_).first(idx.size()), hull_scratch_, hull_idx_);
  if (h < 3) return err(fail(C::DEGENERATE_HULL, 0, static_cast<double>(h)));
  if (h > hull_u.size() || h > hull_v.size())
    return err(fail(C::HULL_TOO_LARGE, 0, static_cast<double>(h)));
  for (std::size_t k = 0; k < h; ++k) {
    hull_u[k] = pu_[hull_idx_[k]];
    hull_v[k] = pv_[hull_idx_[k]];
  }
  return TableModel{plane, hull_u.first(h), hull_v.first(h), check};
}

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
