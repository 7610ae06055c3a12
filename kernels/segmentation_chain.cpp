#include "kernels/segmentation_chain.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "kernels/pixel_subsample.hpp"
#include "kernels/polygonal_prism.hpp"

namespace orthoflow::kernels {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point& start) {
  const auto now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  start = now;
  return ms;
}

/// Indices of the points within tau of the plane (ransac_plane's rule), ascending. @pre out holds them all.
std::size_t collect_inliers(PointsView p, const Plane& plane, float tau, std::span<std::uint32_t> out) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const float dist = plane.normal[0] * p.x[i] + plane.normal[1] * p.y[i] + plane.normal[2] * p.z[i] + plane.d;
    out[n] = static_cast<std::uint32_t>(i);
    n += std::fabs(dist) <= tau ? 1U : 0U;  // false for NaN
  }
  return n;
}

}  // namespace

SegmentationChain::SegmentationChain(std::size_t max_points, const SegmentationParams& params)
    : params_(params), max_points_(max_points), mask_(max_points), kx_(max_points), ky_(max_points), kz_(max_points),
      vx_(max_points), vy_(max_points), vz_(max_points), inliers_(max_points), hull_scratch_(max_points),
      hull_idx_(max_points + 1), pu_(max_points), pv_(max_points), hull_u_(max_points + 1), hull_v_(max_points + 1),
      heights_(max_points), labels_(max_points),
      // every cluster has at least max(1, min_size) points, which bounds the cluster count
      moments_(max_points / std::max<std::size_t>(1, params.cluster.min_size) + 1), stats_(moments_.size()),
      voxel_scratch_(max_points), cluster_scratch_(max_points) {}

Result<std::size_t, SegmentationError> SegmentationChain::filter_and_voxel(CloudView cloud, bool organized,
                                                                           SegmentationTimings& t) {
  auto start = Clock::now();
  if (organized && params_.organized_stride > 0) {
    // The plane and hull need a sample about as dense as the 5 mm voxels, not a voxel grid over every
    // kept pixel: a strided pixel sample costs 1/stride^2 of the frame and needs no sort.
    const std::size_t n = pixel_subsample(cloud, params_.organized_stride, params_.roi, PointsSpan{kx_, ky_, kz_});
    plane_points_ = PointsView{std::span(kx_).first(n), std::span(ky_).first(n), std::span(kz_).first(n)};
    // RANSAC scores its hypotheses on the sample at twice the stride (a quarter of the points); the
    // refit then uses the full sample (fit_plane_on_sample).
    const std::size_t m = pixel_subsample(cloud, 2 * params_.organized_stride, params_.roi, PointsSpan{vx_, vy_, vz_});
    sparse_points_ = PointsView{std::span(vx_).first(m), std::span(vy_).first(m), std::span(vz_).first(m)};
    t.filter = ms_since(start);
    return n;
  }
  const std::size_t kept = crop_box_mask(cloud.points, params_.roi, mask_);
  const PointsSpan kept_span{std::span(kx_).first(kept), std::span(ky_).first(kept), std::span(kz_).first(kept)};
  compact_masked(cloud.points, mask_, kept_span, {});
  t.filter = ms_since(start);
  if (params_.leaf == 0.0F) {
    plane_points_ = kept_span;
    return kept;
  }
  auto voxel_result = voxel_grid(kept_span, params_.leaf, voxel_scratch_, PointsSpan{vx_, vy_, vz_});
  if (!voxel_result) { return err(SegmentationError{voxel_result.error().to_string()}); }
  const std::size_t n = *voxel_result;
  plane_points_ = PointsView{std::span(vx_).first(n), std::span(vy_).first(n), std::span(vz_).first(n)};
  t.voxel = ms_since(start);
  return n;
}

Result<std::size_t, SegmentationError> SegmentationChain::hull_of_inliers(std::size_t inliers) {
  const PlaneBasis basis = make_plane_basis(plane_.plane);
  const auto idx = std::span<const std::uint32_t>(inliers_).first(inliers);
  project_to_plane(plane_points_, idx, basis, pu_, pv_);
  const std::size_t h = convex_hull_2d(std::span<const double>(pu_).first(inliers),
                                       std::span<const double>(pv_).first(inliers), hull_scratch_, hull_idx_);
  if (h < 3) { return err(SegmentationError{"segmentation: the plane inliers have a degenerate hull"}); }
  for (std::size_t k = 0; k < h; ++k) {
    hull_u_[k] = pu_[hull_idx_[k]];
    hull_v_[k] = pv_[hull_idx_[k]];
  }
  return h;
}

Result<std::size_t, SegmentationError> SegmentationChain::objects(CloudView cloud, bool organized,
                                                                  SegmentationTimings& t) {
  auto start = Clock::now();
  auto hull_result = hull_of_inliers(plane_.inliers);
  if (!hull_result) { return hull_result; }
  const std::size_t h = *hull_result;
  const Prism prism{plane_.plane, make_plane_basis(plane_.plane), std::span<const double>(hull_u_).first(h),
                    std::span<const double>(hull_v_).first(h), params_.h_min, params_.h_max,
                    params_.roi};  // the ROI applies to the pixels too (the voxels lie in it already)
  // The prism runs on the full-resolution pixels (organized) or on the plane's input points.
  const PointsView target = organized ? cloud.points : plane_points_;
  polygonal_prism(target, prism, heights_, mask_);
  t.prism = ms_since(start);
  const auto mask = std::span<const std::uint8_t>(mask_).first(target.size());
  auto labels = std::span(labels_).first(target.size());
  auto clusters_result = organized ? euclidean_cluster_organized({target, cloud.width, cloud.height}, mask,
                                                                 params_.cluster, cluster_scratch_, labels)
                                   : euclidean_cluster(target, mask, params_.cluster, cluster_scratch_, labels);
  if (!clusters_result) { return err(SegmentationError{clusters_result.error().to_string()}); }
  const std::size_t clusters = std::min(*clusters_result, stats_.size());
  // Organized: only the pixels the clustering listed (the prism's), not a scan of the whole label frame.
  if (organized) {
    cluster_stats_listed(target, labels, cluster_scratch_.listed_members(), moments_, std::span(stats_).first(clusters));
  } else {
    cluster_stats(target, labels, moments_, std::span(stats_).first(clusters));
  }
  t.cluster = ms_since(start);
  return clusters;
}

Result<std::size_t, SegmentationError> SegmentationChain::fit_plane_on_sample(bool organized) {
  const bool two_level = organized && params_.organized_stride > 0 && sparse_points_.size() >= MIN_SPARSE_POINTS;
  auto ransac_result = ransac_plane(two_level ? sparse_points_ : plane_points_, params_.ransac, inliers_);
  if (!ransac_result) { return err(SegmentationError{ransac_result.error().to_string()}); }
  plane_ = *ransac_result;
  if (!two_level) { return plane_.inliers; }
  // The refit of RANSAC (least squares on the inliers, then the inliers of the refit plane) once more on
  // the full sample: the plane and the hull get the density of the stride-s sample.
  const float tau = params_.ransac.tau;
  const std::size_t first = collect_inliers(plane_points_, plane_.plane, tau, inliers_);
  if (first < 3) { return err(SegmentationError{"segmentation: the plane has fewer than 3 inliers on the sample"}); }
  plane_.plane = fit_plane(plane_points_, std::span<const std::uint32_t>(inliers_).first(first));
  plane_.inliers = collect_inliers(plane_points_, plane_.plane, tau, inliers_);
  return plane_.inliers;
}

Result<SegmentationResult, SegmentationError> SegmentationChain::run(CloudView cloud) {
  if (cloud.points.size() > max_points_) { return err(SegmentationError{"segmentation: cloud larger than max_points"}); }
  const auto start = Clock::now();
  SegmentationTimings t;
  const bool organized = params_.use_organized && cloud.organized();
  if (organized && cloud.points.size() != std::size_t{cloud.width} * cloud.height) {
    return err(SegmentationError{"segmentation: organized cloud of " + std::to_string(cloud.points.size()) +
                                 " points is not " + std::to_string(cloud.width) + " x " +
                                 std::to_string(cloud.height)});
  }
  auto voxel_result = filter_and_voxel(cloud, organized, t);
  if (!voxel_result) { return err(voxel_result.error()); }
  auto plane_start = Clock::now();
  auto plane_result = fit_plane_on_sample(organized);
  if (!plane_result) { return err(plane_result.error()); }
  t.plane = ms_since(plane_start);
  auto objects_result = objects(cloud, organized, t);
  if (!objects_result) { return err(objects_result.error()); }
  t.total = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  const std::size_t n = organized ? cloud.points.size() : plane_points_.size();
  return SegmentationResult{plane_, std::span<const ClusterStats>(stats_).first(*objects_result),
                            std::span<const std::int32_t>(labels_).first(n), organized, t};
}

}  // namespace orthoflow::kernels
