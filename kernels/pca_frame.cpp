#include "kernels/pca_frame.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace orthoflow::kernels {

namespace {

struct Moments {
  std::array<double, 3> origin{};  // the first finite point: the sums below are about it
  std::array<double, 3> sum{};
  std::array<double, 6> sq{};  // xx xy xz yy yz zz
  std::size_t count = 0;
};

// One pass in double about the first finite point: with the shift, sum(d d^T)/m - mean(d) mean(d)^T has
// no catastrophic cancellation for objects metres away from the origin (mug_handle_far is 11 m away).
Moments accumulate(PointsView points) noexcept {
  Moments m;
  bool have_origin = false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x = points.x[i];
    const double y = points.y[i];
    const double z = points.z[i];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) { continue; }
    if (!have_origin) {
      m.origin = {x, y, z};
      have_origin = true;
    }
    const double dx = x - m.origin[0];
    const double dy = y - m.origin[1];
    const double dz = z - m.origin[2];
    m.sum[0] += dx;
    m.sum[1] += dy;
    m.sum[2] += dz;
    m.sq[0] += dx * dx;
    m.sq[1] += dx * dy;
    m.sq[2] += dx * dz;
    m.sq[3] += dy * dy;
    m.sq[4] += dy * dz;
    m.sq[5] += dz * dz;
    ++m.count;
  }
  return m;
}

std::uint32_t shape_flags(const PcaFrame& f) noexcept {
  std::uint32_t flags = 0;
  const double l1 = f.eigenvalues[0];
  if (f.finite < 3) { flags |= FEW_POINTS; }
  if (!(l1 > 0.0) || f.eigenvalues[1] <= FLAT_RATIO * l1) {
    return flags | COLLINEAR | COPLANAR | AXES_AMBIGUOUS;
  }
  if (f.eigenvalues[2] <= FLAT_RATIO * l1) { flags |= COPLANAR; }
  if ((l1 - f.eigenvalues[1]) < AXES_GAP_MIN * l1 || (f.eigenvalues[1] - f.eigenvalues[2]) < AXES_GAP_MIN * l1) {
    flags |= AXES_AMBIGUOUS;
  }
  return flags;
}

}  // namespace

const char* to_string(PcaError error) noexcept {
  switch (error) {
    case PcaError::EMPTY_CLOUD: return "the cloud has no points";
    case PcaError::NO_FINITE_POINTS: return "every point of the cloud has a NaN or infinite coordinate";
  }
  return "unknown PcaError";
}

Result<PcaFrame, PcaError> compute_pca_frame(PointsView points) noexcept {
  if (points.empty()) { return err(PcaError::EMPTY_CLOUD); }
  const Moments m = accumulate(points);
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
  for (int a = 0; a < 3; ++a) { f.centroid[a] = m.origin[a] + mean[a]; }
  // Eigen sorts ascending: column 2 is the largest.
  const Eigen::Vector3d v1 = solver.eigenvectors().col(2);
  const Eigen::Vector3d v2 = solver.eigenvectors().col(1);
  const Eigen::Vector3d v3 = v1.cross(v2);
  for (int a = 0; a < 3; ++a) {
    f.eigenvalues[a] = std::max(solver.eigenvalues()[2 - a], 0.0);
    f.axes[0][a] = v1[a];
    f.axes[1][a] = v2[a];
    f.axes[2][a] = v3[a];
  }
  f.flags = shape_flags(f);
  if (m.count != points.size()) { f.flags |= NAN_IGNORED; }
  return f;
}

}  // namespace orthoflow::kernels
