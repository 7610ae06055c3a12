#pragma once
// SIMD bodies of crop_box_mask() and crop_oriented_mask(): lane-wise comparisons, the mask bytes
// are written from a lane buffer.
#include "kernels/detail/crop_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Batch, class Mask>
inline std::size_t store_mask(const Mask& ok, std::uint8_t* mask) noexcept {
  alignas(64) float buf[Batch::size];
  xsimd::select(ok, Batch(1.0F), Batch(0.0F)).store_aligned(buf);
  std::size_t kept = 0;
  for (std::size_t l = 0; l < Batch::size; ++l) {
    mask[l] = buf[l] != 0.0F ? 1 : 0;
    kept += mask[l];
  }
  return kept;
}

template <class Arch>
std::size_t CropBoxKernel::operator()(Arch /*arch*/, PointsView in, const AxisBox& b,
                                      std::span<std::uint8_t> mask) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = in.size();
  std::size_t kept = 0;
  std::size_t i = 0;
  for (; i + LANES <= n; i += LANES) {
    const batch x = batch::load_unaligned(in.x.data() + i);
    const batch y = batch::load_unaligned(in.y.data() + i);
    const batch z = batch::load_unaligned(in.z.data() + i);
    const auto ok = (x >= batch(b.min[0])) && (x <= batch(b.max[0])) && (y >= batch(b.min[1])) &&
                    (y <= batch(b.max[1])) && (z >= batch(b.min[2])) && (z <= batch(b.max[2]));
    kept += store_mask<batch>(ok, mask.data() + i);
  }
  return kept + crop_box_range(in, b, mask.data(), i, n);
}

template <class Arch>
std::size_t CropOrientedKernel::operator()(Arch /*arch*/, PointsView in, const OrientedBox& b,
                                           std::span<std::uint8_t> mask) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const std::size_t n = in.size();
  std::size_t kept = 0;
  std::size_t i = 0;
  for (; i + LANES <= n; i += LANES) {
    const batch dx = batch::load_unaligned(in.x.data() + i) - batch(b.center[0]);
    const batch dy = batch::load_unaligned(in.y.data() + i) - batch(b.center[1]);
    const batch dz = batch::load_unaligned(in.z.data() + i) - batch(b.center[2]);
    auto ok = dx == dx;  // false for NaN lanes
    for (std::size_t k = 0; k < 3; ++k) {
      const batch t =
          batch(b.axes[3 * k]) * dx + batch(b.axes[3 * k + 1]) * dy + batch(b.axes[3 * k + 2]) * dz;
      ok = ok && (xsimd::abs(t) <= batch(b.half_extent[k]));
    }
    kept += store_mask<batch>(ok, mask.data() + i);
  }
  return kept + crop_oriented_range(in, b, mask.data(), i, n);
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template std::size_t orthoflow::kernels::detail::CropBoxKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView, const orthoflow::kernels::AxisBox&,
    std::span<std::uint8_t>) const noexcept;
template std::size_t orthoflow::kernels::detail::CropOrientedKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, orthoflow::kernels::PointsView, const orthoflow::kernels::OrientedBox&,
    std::span<std::uint8_t>) const noexcept;
#endif
