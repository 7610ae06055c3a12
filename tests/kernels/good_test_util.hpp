#pragma once
// Helpers shared by the GOOD tests: loading the shared vectors, L1 distance, random rigid motions.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "formats/pcd_io.hpp"
#include "kernels/good.hpp"

namespace good_test {

namespace ok = orthoflow::kernels;
namespace fs = std::filesystem;

inline fs::path good_dir() { return fs::path(ORTHOFLOW_SHARED_DIR) / "testdata" / "good"; }

struct Cloud {
  std::vector<float> x, y, z;
  ok::PointsView view() const { return {x, y, z}; }
};

inline Cloud load(const fs::path& path) {
  auto cloud_result = orthoflow::formats::read_pcd(path);
  if (!cloud_result) {
    ADD_FAILURE() << cloud_result.error().to_string();
    return {};
  }
  const ok::PointCloud& pc = cloud_result.value();
  return {{pc.x().begin(), pc.x().end()},
          {pc.y().begin(), pc.y().end()},
          {pc.z().begin(), pc.z().end()}};
}

/// The descriptors after '|' on each "variant ..." line of a .variants or .frames file.
inline std::vector<std::vector<float>> load_variants(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<std::vector<float>> out;
  std::string line;
  while (std::getline(in, line)) {
    const auto bar = line.find('|');
    if (line.rfind("variant ", 0) != 0 || bar == std::string::npos) { continue; }
    std::istringstream values(line.substr(bar + 1));
    std::vector<float> d;
    float v = 0.0F;
    while (values >> v) { d.push_back(v); }
    out.push_back(std::move(d));
  }
  return out;
}

inline double l1(std::span<const float> a, std::span<const float> b) {
  if (a.size() != b.size()) { return 1e9; }
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) { s += std::abs(static_cast<double>(a[i]) - b[i]); }
  return s;
}

/// Smallest L1 distance to any of @p candidates.
inline double best_l1(std::span<const float> d, const std::vector<std::vector<float>>& candidates) {
  double best = 1e9;
  for (const auto& c : candidates) { best = std::min(best, l1(d, c)); }
  return best;
}

/// Applies a seeded random rotation (uniform quaternion) and translation within +-2 m, in double.
inline Cloud random_motion(const Cloud& c, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> t(-2.0, 2.0);
  double q[4] = {g(rng), g(rng), g(rng), g(rng)};
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& v : q) { v /= n; }
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  const double tr[3] = {t(rng), t(rng), t(rng)};
  Cloud out;
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    const double p[3] = {c.x[i], c.y[i], c.z[i]};
    float o[3];
    for (int a = 0; a < 3; ++a) {
      o[a] = static_cast<float>(r[a][0] * p[0] + r[a][1] * p[1] + r[a][2] * p[2] + tr[a]);
    }
    out.x.push_back(o[0]);
    out.y.push_back(o[1]);
    out.z.push_back(o[2]);
  }
  return out;
}

/// compute_good() into a fresh vector; fails the test on error.
inline std::vector<float> describe(const Cloud& c, const ok::GoodConfig& cfg,
                                   ok::GoodResult* result = nullptr) {
  ok::GoodScratch scratch(cfg.bins);
  std::vector<float> d(3 * cfg.bins * cfg.bins);
  auto good_result = ok::compute_good(c.view(), cfg, scratch, d);
  EXPECT_TRUE(good_result.has_value());
  if (good_result && result != nullptr) { *result = good_result.value(); }
  return d;
}

}  // namespace good_test
