#pragma once
// Declarations of the crop SIMD functors; bodies in crop.inl (one TU per arch).
#include <cmath>

#include "kernels/crop.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

struct CropBoxKernel {
  template <class Arch>
  std::size_t operator()(Arch arch, PointsView in, const AxisBox& box,
                         std::span<std::uint8_t> mask) const noexcept;
};

struct CropOrientedKernel {
  template <class Arch>
  std::size_t operator()(Arch arch, PointsView in, const OrientedBox& box,
                         std::span<std::uint8_t> mask) const noexcept;
};

/// Scalar rule for points [begin, end) (shared by the twin and the SIMD tail).
inline std::size_t crop_box_range(PointsView in, const AxisBox& b, std::uint8_t* mask,
                                  std::size_t begin, std::size_t end) noexcept {
  std::size_t kept = 0;
  for (std::size_t i = begin; i < end; ++i) {
    // Written so that NaN fails every comparison.
    const bool ok = in.x[i] >= b.min[0] && in.x[i] <= b.max[0] && in.y[i] >= b.min[1] &&
                    in.y[i] <= b.max[1] && in.z[i] >= b.min[2] && in.z[i] <= b.max[2];
    mask[i] = ok ? 1 : 0;
    kept += ok ? 1U : 0U;
  }
  return kept;
}

/// Scalar rule of the oriented box for points [begin, end).
inline std::size_t crop_oriented_range(PointsView in, const OrientedBox& b, std::uint8_t* mask,
                                       std::size_t begin, std::size_t end) noexcept {
  std::size_t kept = 0;
  for (std::size_t i = begin; i < end; ++i) {
    const float dx = in.x[i] - b.center[0];
    const float dy = in.y[i] - b.center[1];
    const float dz = in.z[i] - b.center[2];
    bool ok = true;
    for (std::size_t k = 0; k < 3; ++k) {
      const float t = b.axes[3 * k] * dx + b.axes[3 * k + 1] * dy + b.axes[3 * k + 2] * dz;
      ok = ok && std::fabs(t) <= b.half_extent[k];
    }
    mask[i] = ok ? 1 : 0;
    kept += ok ? 1U : 0U;
  }
  return kept;
}

}  // namespace orthoflow::kernels::detail
