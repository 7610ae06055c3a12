#include "kernels/point_normals.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

namespace orthoflow::kernels {

std::string PointNormalError::to_string() const {
  switch (code) {
    case Code::INVALID_RADIUS:
      return "point normals: the radius must be finite and > 0, got " + std::to_string(value);
    case Code::BAD_INDEX:
      return "point normals: index " + std::to_string(static_cast<std::uint64_t>(value)) +
             " is past the last point";
    case Code::OUTPUT_TOO_SMALL:
      return "point normals: the output holds " +
             std::to_string(static_cast<std::uint64_t>(value)) + " points, fewer than the view";
  }
  return "point normals: unknown error";
}

namespace {

bool finite(float x, float y, float z) noexcept {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
}

/// The normal at point q, or false (too few neighbours, q not finite, a degenerate covariance).
bool normal_at(PointsView p, std::size_t q, const PointNormalParams& params, Eigen::Vector3d& n) {
  const float qx = p.x[q], qy = p.y[q], qz = p.z[q];
  if (!finite(qx, qy, qz)) return false;
  const float r2 = params.radius * params.radius;
  // Two passes in double about the first neighbour's offset (q itself): stable for points far
  // from the origin, and the same sums in the same order everywhere.
  std::size_t count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const float dx = p.x[i] - qx, dy = p.y[i] - qy, dz = p.z[i] - qz;
    const float d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 <= r2)) continue;  // NaN and Inf points fail here
    const Eigen::Vector3d d(dx, dy, dz);
    sum += d;
    outer += d * d.transpose();
    ++count;
  }
  if (count < params.min_neighbours || count < 3) return false;
  const double inv = 1.0 / static_cast<double>(count);
  const Eigen::Vector3d mean = sum * inv;
  const Eigen::Matrix3d cov = outer * inv - mean * mean.transpose();
  if (!cov.allFinite() || cov.trace() <= 0.0) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success) return false;
  n = eig.eigenvectors().col(0);  // eigenvalues ascending: the smallest first
  const Eigen::Vector3d to_view(params.viewpoint[0] - qx, params.viewpoint[1] - qy,
                                params.viewpoint[2] - qz);
  if (to_view.dot(n) < 0.0) n = -n;
  return n.allFinite();
}

}  // namespace

Result<std::size_t, PointNormalError> point_normals(PointsView points,
                                                    std::span<const std::uint32_t> at,
                                                    const PointNormalParams& params,
                                                    PointsSpan out) noexcept {
  using Code = PointNormalError::Code;
  if (!std::isfinite(params.radius) || params.radius <= 0.0F)
    return err(PointNormalError{Code::INVALID_RADIUS, params.radius});
  if (out.size() < points.size())
    return err(PointNormalError{Code::OUTPUT_TOO_SMALL, static_cast<double>(out.size())});
  for (const std::uint32_t i : at)
    if (i >= points.size()) return err(PointNormalError{Code::BAD_INDEX, static_cast<double>(i)});
  std::size_t good = 0;
  constexpr float NaN = std::numeric_limits<float>::quiet_NaN();
  for (const std::uint32_t i : at) {
    Eigen::Vector3d n;
    if (normal_at(points, i, params, n)) {
      out.x[i] = static_cast<float>(n.x());
      out.y[i] = static_cast<float>(n.y());
      out.z[i] = static_cast<float>(n.z());
      ++good;
    } else {
      out.x[i] = out.y[i] = out.z[i] = NaN;
    }
  }
  return good;
}

}  // namespace orthoflow::kernels
