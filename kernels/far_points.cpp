#include "kernels/far_points.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace orthoflow::kernels {

namespace {

bool finite_point(PointsView p, std::size_t i) noexcept {
  return std::isfinite(p.x[i]) && std::isfinite(p.y[i]) && std::isfinite(p.z[i]);
}

double squared_distance(PointsView p, std::size_t i, const std::array<double, 3>& c) noexcept {
  const double dx = static_cast<double>(p.x[i]) - c[0];
  const double dy = static_cast<double>(p.y[i]) - c[1];
  const double dz = static_cast<double>(p.z[i]) - c[2];
  return dx * dx + dy * dy + dz * dz;
}

// The per-point test in float, branch-free so the counting loop vectorises: IEEE float without
// contraction (-ffp-contract=off), so x86 and ARM agree bit for bit. A finite point so far that its
// squared distance overflows is inf > limit: far. A non-finite coordinate makes v - v NaN: not far.
struct FarTest {
  float cx, cy, cz, limit2;
  [[nodiscard]] bool far(float x, float y, float z) const noexcept {
    const float dx = x - cx;
    const float dy = y - cy;
    const float dz = z - cz;
    const bool finite = ((x - x) + (y - y) + (z - z)) == 0.0F;
    return finite & (dx * dx + dy * dy + dz * dz > limit2);
  }
};

FarTest far_test(const FarPoints& far) noexcept {
  const auto limit = static_cast<float>(far.keep_radius);
  return {static_cast<float>(far.centre[0]), static_cast<float>(far.centre[1]),
          static_cast<float>(far.centre[2]), limit * limit};
}

// The value of rank floor(q (n - 1)) in values[0, n) (q = 1/2: the lower median); @pre n > 0.
// Reorders the values.
double quantile_of(std::array<double, FAR_POINT_SAMPLES>& values, std::size_t n,
                   std::size_t tenths) noexcept {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(tenths * (n - 1) / 10);
  std::nth_element(values.begin(), mid, values.begin() + static_cast<std::ptrdiff_t>(n));
  return *mid;
}

}  // namespace

FarPoints find_far_points(PointsView points) noexcept {
  FarPoints far;
  const std::size_t n = points.size();
  if (n == 0) { return far; }
  // Sample indices floor(k n / S) for k < S: every point when n <= S, an even stride otherwise.
  std::array<std::size_t, FAR_POINT_SAMPLES> picked{};
  std::size_t m = 0;
  const std::size_t samples = std::min(n, FAR_POINT_SAMPLES);
  for (std::size_t k = 0; k < samples; ++k) {
    const std::size_t i = k * n / samples;
    if (finite_point(points, i)) { picked[m++] = i; }
  }
  far.keep_radius = std::numeric_limits<double>::infinity();
  if (m < FAR_POINT_MIN_SAMPLES) { return far; }  // too few to judge by: nothing is far
  std::array<double, FAR_POINT_SAMPLES> values{};
  const std::span<const float> axes[3] = {points.x, points.y, points.z};
  for (std::size_t a = 0; a < 3; ++a) {
    for (std::size_t k = 0; k < m; ++k) { values[k] = axes[a][picked[k]]; }
    far.centre[a] = quantile_of(values, m, 5);
  }
  for (std::size_t k = 0; k < m; ++k) {
    values[k] = squared_distance(points, picked[k], far.centre);
  }
  const double radius = std::sqrt(quantile_of(values, m, 9));
  far.keep_radius = std::max(FAR_POINT_FACTOR * radius, FAR_POINT_FLOOR_M);
  const FarTest test = far_test(far);
  const float* x = points.x.data();
  const float* y = points.y.data();
  const float* z = points.z.data();
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) { count += test.far(x[i], y[i], z[i]) ? 1U : 0U; }
  far.count = count;
  return far;
}

bool is_far_point(PointsView points, std::size_t i, const FarPoints& far) noexcept {
  return far_test(far).far(points.x[i], points.y[i], points.z[i]);
}

std::size_t copy_near_points(PointsView points, const FarPoints& far, PointsSpan out) noexcept {
  const FarTest test = far_test(far);
  std::size_t written = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (test.far(points.x[i], points.y[i], points.z[i])) { continue; }
    out.x[written] = points.x[i];
    out.y[written] = points.y[i];
    out.z[written] = points.z[i];
    ++written;
  }
  return written;
}

}  // namespace orthoflow::kernels
