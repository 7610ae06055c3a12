#pragma once
// Helpers shared by the formats tests: small clouds with every field, and bitwise comparison.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "kernels/point_cloud.hpp"

namespace orthoflow::test {

inline std::uint32_t bits(float v) {
  std::uint32_t b = 0;
  std::memcpy(&b, &v, 4);
  return b;
}

/// A width x height cloud with random coordinates (some NaN) and, if asked, every optional field.
inline kernels::PointCloud make_cloud(std::uint32_t width, std::uint32_t height, bool all_fields,
                                      std::uint32_t seed) {
  kernels::PointCloud c;
  if (all_fields) {
    c.add_field(kernels::Field::RGB);
    c.add_field(kernels::Field::LABEL);
    c.add_field(kernels::Field::NORMALS);
  }
  c.resize(width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-5.0F, 5.0F);
  for (std::size_t i = 0; i < c.size(); ++i) {
    const bool nan = (rng() % 7) == 0;
    c.x()[i] = nan ? std::numeric_limits<float>::quiet_NaN() : u(rng);
    c.y()[i] = nan ? std::numeric_limits<float>::quiet_NaN() : u(rng);
    c.z()[i] = nan ? std::numeric_limits<float>::quiet_NaN() : u(rng) * 1e-7F;
    if (all_fields) {
      c.rgb()[i] = static_cast<std::uint32_t>(rng());
      c.label()[i] = static_cast<std::uint32_t>(rng() % 100000);
      c.normal_x()[i] = u(rng);
      c.normal_y()[i] = u(rng);
      c.normal_z()[i] = u(rng);
    }
  }
  c.info.viewpoint.origin = {0.5F, -1.25F, 3.0F};
  c.info.viewpoint.orientation = {0.5F, 0.5F, 0.5F, 0.5F};
  return c;
}

/// Coordinates compared by bits (NaN equals NaN), then every optional field.
inline void expect_same_cloud(const kernels::PointCloud& a, const kernels::PointCloud& b) {
  ASSERT_EQ(a.width(), b.width());
  ASSERT_EQ(a.height(), b.height());
  ASSERT_EQ(a.size(), b.size());
  for (auto f : {kernels::Field::RGB, kernels::Field::LABEL, kernels::Field::NORMALS}) {
    ASSERT_EQ(a.has(f), b.has(f));
  }
  std::size_t mismatches = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const bool same =
        bits(a.x()[i]) == bits(b.x()[i]) && bits(a.y()[i]) == bits(b.y()[i]) &&
        bits(a.z()[i]) == bits(b.z()[i]) &&
        (!a.has(kernels::Field::RGB) || a.rgb()[i] == b.rgb()[i]) &&
        (!a.has(kernels::Field::LABEL) || a.label()[i] == b.label()[i]) &&
        (!a.has(kernels::Field::NORMALS) || (bits(a.normal_x()[i]) == bits(b.normal_x()[i]) &&
                                             bits(a.normal_y()[i]) == bits(b.normal_y()[i]) &&
                                             bits(a.normal_z()[i]) == bits(b.normal_z()[i])));
    mismatches += same ? 0U : 1U;
  }
  EXPECT_EQ(mismatches, 0U);
}

}  // namespace orthoflow::test
