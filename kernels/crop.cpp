#include "kernels/crop.hpp"

#include <limits>

#include "core/assert.hpp"
#include "kernels/detail/crop_kernel.hpp"

namespace orthoflow::kernels {

std::size_t crop_box_mask_scalar(PointsView in, const AxisBox& box,
                                 std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= in.size(), "crop_box_mask: mask shorter than the input");
  return detail::crop_box_range(in, box, mask.data(), 0, in.size());
}

std::size_t crop_box_mask(PointsView in, const AxisBox& box,
                          std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= in.size(), "crop_box_mask: mask shorter than the input");
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::CropBoxKernel{});
  return dispatched(in, box, mask);
}

std::size_t crop_oriented_mask_scalar(PointsView in, const OrientedBox& box,
                                      std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= in.size(), "crop_oriented_mask: mask shorter than the input");
  return detail::crop_oriented_range(in, box, mask.data(), 0, in.size());
}

std::size_t crop_oriented_mask(PointsView in, const OrientedBox& box,
                               std::span<std::uint8_t> mask) noexcept {
  OF_ASSERT(mask.size() >= in.size(), "crop_oriented_mask: mask shorter than the input");
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::CropOrientedKernel{});
  return dispatched(in, box, mask);
}

std::size_t compact_masked(PointsView in, std::span<const std::uint8_t> mask, PointsSpan out,
                           std::span<std::uint32_t> indices) noexcept {
  std::size_t w = 0;
  const bool with_indices = !indices.empty();
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (mask[i] == 0) { continue; }
    OF_ASSERT(w < out.size(), "compact_masked: output too small");
    out.x[w] = in.x[i];
    out.y[w] = in.y[i];
    out.z[w] = in.z[i];
    if (with_indices) { indices[w] = static_cast<std::uint32_t>(i); }
    ++w;
  }
  return w;
}

std::size_t mask_organized(PointsView in, std::span<const std::uint8_t> mask,
                           PointsSpan out) noexcept {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const bool keep = mask[i] != 0;
    out.x[i] = keep ? in.x[i] : nan;
    out.y[i] = keep ? in.y[i] : nan;
    out.z[i] = keep ? in.z[i] : nan;
    kept += keep ? 1U : 0U;
  }
  return kept;
}

}  // namespace orthoflow::kernels
