#include "evaluation/derived_views.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.hpp"

namespace orthoflow::evaluation {

kernels::PointCloud derive_view(const kernels::PointCloud& cloud, std::uint32_t index,
                                std::uint64_t seed) {
  std::vector<std::size_t> finite;
  double c[3] = {0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (std::isfinite(cloud.x()[i]) && std::isfinite(cloud.y()[i]) && std::isfinite(cloud.z()[i])) {
      finite.push_back(i);
      c[0] += cloud.x()[i];
      c[1] += cloud.y()[i];
      c[2] += cloud.z()[i];
    }
  }
  kernels::PointCloud out;
  if (finite.empty()) { return out; }
  for (double& v : c) { v /= static_cast<double>(finite.size()); }
  core::Rng rng(seed * 0x9E3779B97F4A7C15ULL + index);
  // A random direction (normalised Gaussian vector) and the share of points to keep along it.
  double d[3] = {rng.normal(), rng.normal(), rng.normal()};
  const double norm = std::max(1e-12, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
  const double keep = index == 0 ? 1.0 : rng.uniform(0.7, 1.0);
  std::vector<std::pair<double, std::size_t>> along;
  for (const std::size_t i : finite) {
    const double t = ((cloud.x()[i] - c[0]) * d[0] + (cloud.y()[i] - c[1]) * d[1] +
                      (cloud.z()[i] - c[2]) * d[2]) /
                     norm;
    along.emplace_back(t, i);
  }
  std::sort(along.begin(), along.end());
  const auto kept =
      std::max<std::size_t>(1, static_cast<std::size_t>(keep * static_cast<double>(along.size())));
  std::sort(
      along.begin(), along.begin() + static_cast<std::ptrdiff_t>(kept),
      [](const auto& a, const auto& b) { return a.second < b.second; });  // original point order
  out.resize_unorganized(kept);
  const double sigma = index == 0 ? 0.0 : 0.001;
  for (std::size_t k = 0; k < kept; ++k) {
    const std::size_t i = along[k].second;
    out.x()[k] = static_cast<float>(cloud.x()[i] + sigma * rng.normal());
    out.y()[k] = static_cast<float>(cloud.y()[i] + sigma * rng.normal());
    out.z()[k] = static_cast<float>(cloud.z()[i] + sigma * rng.normal());
  }
  return out;
}

}  // namespace orthoflow::evaluation
