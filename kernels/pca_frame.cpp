#include "kernels/pca_frame.hpp"

#include "kernels/detail/pca_moments_kernel.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace orthoflow::kernels {

namespace {

std::uint32_t shape_flags(const PcaFrame& f) noexcept {
  std::uint32_t flags = 0;
  const double l1 = f.eigenvalues[0];
  if (f.finite < 3) { flags |= FEW_POINTS; }
  if (!(l1 > 0.0) || f.eigenvalues[1] <= FLAT_RATIO * l1) {
    return flags | COLLINEAR | COPLANAR | AXES_AMBIGUOUS;
  }
  if (f.eigenvalues[2] <= FLAT_RATIO * l1) { flags |= COPLANAR; }
  if ((l1 - f.eigenvalues[1]) < AXES_GAP_MIN * l1 ||
      (f.eigenvalues[1] - f.eigenvalues[2]) < AXES_GAP_MIN * l1) {
    flags |= AXES_AMBIGUOUS;
  }
  return flags;
}

}  // namespace

const char* to_string(PcaError error) noexcept {
  switch (error) {
    case PcaError::EMPTY_CLOUD:
      return "the cloud has no points";
    case PcaError::NO_FINITE_POINTS:
      return "every point of the cloud has a NaN or infinite coordinate";
  }
  return "unknown PcaError";
}

PcaMoments pca_moments_scalar(PointsView points) noexcept {
  PcaMoments m;
  const std::size_t first = detail::first_finite(points);
  if (first == points.size()) { return m; }
  // Sums about the first finite point: sum(d d^T)/m - mean(d) mean(d)^T then has no catastrophic
  // cancellation for objects metres away from the origin (mug_handle_far is 11 m away).
  m.origin = {points.x[first], points.y[first], points.z[first]};
  detail::add_moments_scalar(points, first, points.size(), m);
  return m;
}

PcaMoments pca_moments(PointsView points) noexcept {
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::PcaMomentsKernel{});
  PcaMoments m;
  const std::size_t first = detail::first_finite(points);
  if (first == points.size()) { return m; }
  m.origin = {points.x[first], points.y[first], points.z[first]};
  return dispatched(points, m);
}

Result<PcaFrame, PcaError> compute_pca_frame(PointsView points) noexcept {
  if (points.empty()) { return err(PcaError::EMPTY_CLOUD); }
  return pca_frame_from_moments(pca_moments(points), points.size());
}

Result<PcaFrame, PcaError> compute_pca_frame_scalar(PointsView points) noexcept {
  if (points.empty()) { return err(PcaError::EMPTY_CLOUD); }
  return pca_frame_from_moments(pca_moments_scalar(points), points.size());
}

Result<PcaFrame, PcaError> pca_frame_from_moments(const PcaMoments& m,
                                                  std::size_t total_points) noexcept {
  if (total_points == 0) { return err(PcaError::EMPTY_CLOUD); }
  if (m.count == 0) { return err(PcaError::NO_FINITE_POINTS); }
  const double inv = 1.0 / static_cast<double>(m.count);
  const Eigen::Vector3d mean(m.sum[0] * inv, m.sum[1] * inv, m.sum[2] * inv);
  Eigen::Matrix3d cov;
  cov << m.sq[0] * inv, m.sq[1] * inv, m.sq[2] * inv,  //
      m.sq[1] * inv, m.sq[3] * inv, m.sq[4] * inv,     //
      m.sq[2] * inv, m.sq[4] * inv, m.sq[5] * inv;
  cov -= mean * mean.transpose();  // C = E[d d^T] - E[d] E[d]^T (population covariance, /m)
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov, Eigen::ComputeEigenvectors);
  PcaFrame f;
  f.finite = m.count;
  for (std::size_t a = 0; a < 3; ++a) {
    f.centroid[a] = m.origin[a] + mean[static_cast<Eigen::Index>(a)];
  }
  // Eigen sorts ascending: column 2 is the largest.
  const Eigen::Vector3d v1 = solver.eigenvectors().col(2);
  const Eigen::Vector3d v2 = solver.eigenvectors().col(1);
  const Eigen::Vector3d v3 = v1.cross(v2);
  for (std::size_t a = 0; a < 3; ++a) {
    const auto e = static_cast<Eigen::Index>(a);
    f.eigenvalues[a] = std::max(solver.eigenvalues()[2 - e], 0.0);
    f.axes[0][a] = v1[e];
    f.axes[1][a] = v2[e];
    f.axes[2][a] = v3[e];
  }
  f.flags = shape_flags(f);
  if (m.count != total_points) { f.flags |= NAN_IGNORED; }
  return f;
}

}  // namespace orthoflow::kernels
