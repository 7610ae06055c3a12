#pragma once
/// @file
/// @brief A frame as many recordings and ROS bags store a Kinect cloud: its points without the
/// invalid (NaN-depth) pixels, in stored (row-major) order, HEIGHT 1, with the rgb and label
/// fields it had. For the tests and benchmarks of kernels/pinhole_regrid.hpp and the unorganized
/// path.
#include <cmath>
#include <cstddef>

#include "kernels/point_cloud.hpp"

namespace orthoflow::test {

inline kernels::PointCloud unorganized_copy(const kernels::PointCloud& organized) {
  using kernels::Field;
  kernels::PointCloud flat;
  const bool rgb = organized.has(Field::RGB), label = organized.has(Field::LABEL);
  if (rgb) flat.add_field(Field::RGB);
  if (label) flat.add_field(Field::LABEL);
  std::size_t n = 0;
  for (std::size_t i = 0; i < organized.size(); ++i) n += std::isfinite(organized.z()[i]) ? 1 : 0;
  flat.resize_unorganized(n);
  for (std::size_t i = 0, k = 0; i < organized.size(); ++i) {
    if (!std::isfinite(organized.z()[i])) continue;
    flat.x()[k] = organized.x()[i];
    flat.y()[k] = organized.y()[i];
    flat.z()[k] = organized.z()[i];
    if (rgb) flat.rgb()[k] = organized.rgb()[i];
    if (label) flat.label()[k] = organized.label()[i];
    ++k;
  }
  flat.info = organized.info;
  return flat;
}

}  // namespace orthoflow::test
