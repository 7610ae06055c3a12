#pragma once
// The kernel benchmarks' point clouds: a structure of arrays with its view, and random points in a
// cube with every tenth point NaN.
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "kernels/point_cloud.hpp"

namespace orthoflow::bench {

struct Cloud {
  std::vector<float> x, y, z;
  kernels::PointsView view() const { return {x, y, z}; }
};

/// @brief n points uniform in [-half, half]^3 shifted by z_offset along z, every tenth x NaN.
inline Cloud random_cube(std::size_t n, float half, float z_offset) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> c(-half, half);
  Cloud out;
  for (std::size_t i = 0; i < n; ++i) {
    out.x.push_back(i % 10 == 0 ? std::numeric_limits<float>::quiet_NaN() : c(rng));
    out.y.push_back(c(rng));
    out.z.push_back(c(rng) + z_offset);
  }
  return out;
}

}  // namespace orthoflow::bench
