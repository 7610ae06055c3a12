#include "kernels/ransac_plane.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/rng.hpp"
#include "kernels/detail/number_text.hpp"

namespace orthoflow::kernels {

std::string RansacError::to_string() const {
  switch (code) {
    case Code::BAD_PARAMS:
      return "ransac_plane: invalid parameter value " + detail::value_text(value);
    case Code::TOO_FEW_POINTS:
      return "ransac_plane: " + detail::count_text(value) + " finite points, need at least 3";
    case Code::NO_HYPOTHESIS:
      return "ransac_plane: all " + detail::count_text(value) + " draws were degenerate";
    case Code::OUTPUT_TOO_SMALL:
      return "ransac_plane: inlier output too small for " + detail::count_text(value);
  }
  return "ransac_plane: unknown error";
}

namespace {

using Vec = Eigen::Vector3d;

Vec point(PointsView p, std::size_t i) { return {p.x[i], p.y[i], p.z[i]}; }
bool finite_at(PointsView p, std::size_t i) {
  return std::isfinite(p.x[i]) && std::isfinite(p.y[i]) && std::isfinite(p.z[i]);
}

/// A plane through 3 random finite points, or false when the draw is degenerate: repeated index,
/// coincident or collinear points (sine of the angle between the edges below 1e-6).
bool draw_hypothesis(PointsView pts, core::Rng& rng, Plane& out) {
  const auto n = pts.size();
  const auto i0 = rng.below(n), i1 = rng.below(n), i2 = rng.below(n);
  if (i0 == i1 || i0 == i2 || i1 == i2 || !finite_at(pts, i0) || !finite_at(pts, i1) ||
      !finite_at(pts, i2)) {
    return false;
  }
  const Vec p0 = point(pts, i0);
  const Vec e1 = point(pts, i1) - p0;
  const Vec e2 = point(pts, i2) - p0;
  const Vec normal = e1.cross(e2);
  const double norm = normal.norm();
  if (!(norm > 1e-6 * e1.norm() * e2.norm())) { return false; }
  const Vec unit = normal / norm;
  out.normal = {static_cast<float>(unit.x()), static_cast<float>(unit.y()),
                static_cast<float>(unit.z())};
  out.d = static_cast<float>(-unit.dot(p0));
  return true;
}

/// Hypotheses needed for @p confidence of one outlier-free sample at inlier ratio w
/// (Fischler-Bolles).
double needed_iterations(double confidence, double w) {
  const double w3 = w * w * w;
  if (w3 >= 1.0) { return 1.0; }
  if (w3 <= 0.0) { return 1e300; }
  return std::log(1.0 - confidence) / std::log(1.0 - w3);
}

/// Writes the indices within tau of @p plane; returns how many there are (stops writing at
/// capacity).
std::size_t collect_inliers(PointsView pts, const Plane& plane, float tau,
                            std::span<std::uint32_t> out) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const float dist = plane.normal[0] * pts.x[i] + plane.normal[1] * pts.y[i] +
                       plane.normal[2] * pts.z[i] + plane.d;
    if (!(std::fabs(dist) <= tau)) { continue; }
    if (n < out.size()) { out[n] = static_cast<std::uint32_t>(i); }
    ++n;
  }
  return n;
}

/// Least-squares refit on the hypothesis's inliers, then the inliers of the refit plane.
Result<RansacPlane, RansacError> refine(PointsView pts, const Plane& hypothesis, float tau,
                                        std::uint32_t iterations, std::span<std::uint32_t> out) {
  const std::size_t first = collect_inliers(pts, hypothesis, tau, out);
  if (first > out.size()) {
    return err(RansacError{RansacError::Code::OUTPUT_TOO_SMALL, double(first)});
  }
  const Plane refit = fit_plane(pts, out.first(first));
  const std::size_t second = collect_inliers(pts, refit, tau, out);
  if (second > out.size()) {
    return err(RansacError{RansacError::Code::OUTPUT_TOO_SMALL, double(second)});
  }
  return RansacPlane{refit, second, iterations};
}

template <class Counter>
Result<RansacPlane, RansacError> ransac_impl(PointsView pts, const RansacParams& prm,
                                             std::span<std::uint32_t> out, Counter count) noexcept {
  using Code = RansacError::Code;
  if (!std::isfinite(prm.tau) || prm.tau < 0.0F) {
    return err(RansacError{Code::BAD_PARAMS, prm.tau});
  }
  if (prm.max_iterations == 0) { return err(RansacError{Code::BAD_PARAMS, 0.0}); }
  if (!(prm.confidence >= 0.0 && prm.confidence < 1.0)) {
    return err(RansacError{Code::BAD_PARAMS, prm.confidence});
  }
  std::size_t finite = 0;
  for (std::size_t i = 0; i < pts.size() && finite < 3; ++i) {
    finite += finite_at(pts, i) ? 1U : 0U;
  }
  if (finite < 3) { return err(RansacError{Code::TOO_FEW_POINTS, double(finite)}); }
  core::Rng rng(prm.seed);
  const auto& up = prm.up;
  const bool prior = up[0] != 0.0F || up[1] != 0.0F || up[2] != 0.0F;
  const float min_cos = std::cos(std::clamp(prm.max_tilt_deg, 0.0F, 90.0F) * 0.0174532925F);
  const auto level = [&](const Plane& h) {
    return !prior ||
           std::fabs(h.normal[0] * up[0] + h.normal[1] * up[1] + h.normal[2] * up[2]) >= min_cos;
  };
  Plane best;
  std::size_t best_count = 0;
  std::uint32_t it = 0;
  // A degenerate draw is redrawn (up to 100 times) within the same iteration.
  for (; it < prm.max_iterations; ++it) {
    Plane hypothesis;
    bool ok = false;
    for (int attempt = 0; attempt < 100 && !ok; ++attempt) {
      ok = draw_hypothesis(pts, rng, hypothesis) && level(hypothesis);
    }
    if (!ok) { continue; }
    const std::size_t c = count(pts, hypothesis, prm.tau);
    if (c > best_count) {
      best_count = c;
      best = hypothesis;
    }
    const double w = static_cast<double>(best_count) / static_cast<double>(pts.size());
    if (prm.confidence > 0.0 &&
        static_cast<double>(it + 1) >= needed_iterations(prm.confidence, w)) {
      ++it;
      break;
    }
  }
  if (best_count < 3) { return err(RansacError{Code::NO_HYPOTHESIS, double(it)}); }
  auto refined = refine(pts, best, prm.tau, it, out);
  // A near-collinear draw can pass the prior and score a strip of a wall, whose refit is the wall.
  if (refined && !level(refined->plane)) {
    return err(RansacError{Code::NO_HYPOTHESIS, double(it)});
  }
  return refined;
}

}  // namespace

Plane fit_plane(PointsView pts, std::span<const std::uint32_t> indices) noexcept {
  Vec mean = Vec::Zero();
  for (const std::uint32_t i : indices) { mean += point(pts, i); }
  mean /= static_cast<double>(indices.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const std::uint32_t i : indices) {
    const Vec q = point(pts, i) - mean;
    cov += q * q.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(cov);  // eigenvalues ascending: column 0 is the normal
  Vec normal = solver.eigenvectors().col(0).normalized();
  double d = -normal.dot(mean);
  if (d < 0.0) {  // the sensor (origin) on the positive side: heights above the table are > 0
    normal = -normal;
    d = -d;
  }
  return Plane{{static_cast<float>(normal.x()), static_cast<float>(normal.y()),
                static_cast<float>(normal.z())},
               static_cast<float>(d)};
}

Result<RansacPlane, RansacError> ransac_plane(PointsView points, const RansacParams& params,
                                              std::span<std::uint32_t> inliers_out) noexcept {
  return ransac_impl(points, params, inliers_out, [](PointsView p, const Plane& pl, float tau) {
    return count_plane_inliers(p, pl, tau);
  });
}

Result<RansacPlane, RansacError> ransac_plane_scalar(
    PointsView points, const RansacParams& params, std::span<std::uint32_t> inliers_out) noexcept {
  return ransac_impl(points, params, inliers_out, [](PointsView p, const Plane& pl, float tau) {
    return count_plane_inliers_scalar(p, pl, tau);
  });
}

}  // namespace orthoflow::kernels
