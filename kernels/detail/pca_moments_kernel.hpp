#pragma once
// Declaration of the pca_moments() SIMD functor (body in pca_moments.inl) and the scalar rule
// shared by the twin and the SIMD tail.
#include <cmath>
#include <cstddef>

#include "kernels/pca_frame.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

struct PcaMomentsKernel {
  /// Adds points [0, n) to moments whose origin is already set.
  template <class Arch>
  PcaMoments operator()(Arch arch, PointsView points, PcaMoments m) const noexcept;
};

/// Index of the first point with three finite coordinates, or points.size().
inline std::size_t first_finite(PointsView points) noexcept {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (std::isfinite(points.x[i]) && std::isfinite(points.y[i]) && std::isfinite(points.z[i])) {
      return i;
    }
  }
  return points.size();
}

/// Adds points [begin, end) to @p m about m.origin (non-finite points skipped).
inline void add_moments_scalar(PointsView points, std::size_t begin, std::size_t end,
                               PcaMoments& m) noexcept {
  for (std::size_t i = begin; i < end; ++i) {
    if (!std::isfinite(points.x[i]) || !std::isfinite(points.y[i]) || !std::isfinite(points.z[i])) {
      continue;
    }
    const double dx = static_cast<double>(points.x[i]) - m.origin[0];
    const double dy = static_cast<double>(points.y[i]) - m.origin[1];
    const double dz = static_cast<double>(points.z[i]) - m.origin[2];
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
}

}  // namespace orthoflow::kernels::detail
