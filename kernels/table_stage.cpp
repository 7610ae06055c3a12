// Stage 2 of the tabletop chain (kernels/tabletop_stages.hpp): TableStage, the RANSAC plane
// refined on the dense sample, the other-level check (PlaneCheck) and the convex hull of the
// inliers.
#include <cmath>

#include "kernels/detail/stage_common.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels {

namespace {

using detail::fail;

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

}  // namespace

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

}  // namespace orthoflow::kernels
