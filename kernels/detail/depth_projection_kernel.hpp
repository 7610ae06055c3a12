#pragma once
// Declaration of the depth_to_points() SIMD functor; body in depth_projection.inl (one TU per
// arch).
#include <cmath>
#include <limits>

#include "kernels/depth_projection.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

struct DepthProjectionKernel {
  template <class Arch>
  std::size_t operator()(Arch arch, std::span<const std::uint16_t> raw, std::uint32_t width,
                         std::uint32_t height, std::span<const float, DISPARITY_TABLE_SIZE> table_m,
                         const DepthCamera& camera, PointsSpan out) const noexcept;
};

/// Projects pixels [begin, end) of row v with the scalar rule (shared by the twin and the SIMD
/// tail).
inline std::size_t project_row_scalar(const std::uint16_t* raw, std::size_t begin, std::size_t end,
                                      float ray_y, const float* table, const DepthCamera& camera,
                                      float* x, float* y, float* z) noexcept {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inv_fx = 1.0F / camera.fx;
  std::size_t valid = 0;
  for (std::size_t u = begin; u < end; ++u) {
    const float depth = table[raw[u] & 0x7FFU];
    if (!(depth > 0.0F)) {
      x[u] = y[u] = z[u] = nan;
      continue;
    }
    x[u] = ((static_cast<float>(u) - camera.cx) * inv_fx) * depth;
    y[u] = ray_y * depth;
    z[u] = depth;
    ++valid;
  }
  return valid;
}

}  // namespace orthoflow::kernels::detail
