#pragma once
// Declarations of the plane-distance SIMD functors; bodies in plane_distance.inl (one TU per arch).
#include <cmath>

#include "kernels/plane_distance.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

struct PlaneInlierKernel {
  template <class Arch>
  std::size_t operator()(Arch arch, PointsView points, const Plane& plane,
                         float tau) const noexcept;
};

struct PlaneDistanceKernel {
  template <class Arch>
  std::size_t operator()(Arch arch, PointsView points, const Plane& plane,
                         std::span<float> out) const noexcept;
};

/// The scalar distance rule shared by the twins and the SIMD tails.
inline float plane_distance(const Plane& p, float x, float y, float z) noexcept {
  return p.normal[0] * x + p.normal[1] * y + p.normal[2] * z + p.d;
}

inline std::size_t count_inliers_range(PointsView pts, const Plane& plane, float tau,
                                       std::size_t begin, std::size_t end) noexcept {
  std::size_t count = 0;
  for (std::size_t i = begin; i < end; ++i) {
    count += std::fabs(plane_distance(plane, pts.x[i], pts.y[i], pts.z[i])) <= tau ? 1U : 0U;
  }
  return count;
}

}  // namespace orthoflow::kernels::detail
