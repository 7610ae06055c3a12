#pragma once
// SIMD body of depth_to_points(): the table lookup is a scalar gather into a lane buffer (no
// portable float gather before AVX2), the ray scaling and the validity mask are vector operations.
#include <cstdint>

#include "kernels/detail/depth_projection_kernel.hpp"

namespace orthoflow::kernels::detail {

template <class Arch>
std::size_t DepthProjectionKernel::operator()(Arch /*arch*/, std::span<const std::uint16_t> raw,
                                              std::uint32_t width, std::uint32_t height,
                                              std::span<const float, DISPARITY_TABLE_SIZE> table_m,
                                              const DepthCamera& camera,
                                              PointsSpan out) const noexcept {
  using batch = xsimd::batch<float, Arch>;
  constexpr std::size_t LANES = batch::size;
  const float inv_fx = 1.0F / camera.fx;
  const float inv_fy = 1.0F / camera.fy;
  const batch nan(std::numeric_limits<float>::quiet_NaN());
  alignas(64) float depth_buf[LANES];
  alignas(64) float u_buf[LANES];
  std::size_t valid = 0;
  for (std::size_t v = 0; v < height; ++v) {
    const std::size_t row = v * width;
    const float ray_y = (static_cast<float>(v) - camera.cy) * inv_fy;
    const std::uint16_t* r = raw.data() + row;
    std::size_t u = 0;
    batch row_count(0.0F);  // exact: a row has far fewer than 2^24 pixels per lane
    for (; u + LANES <= width; u += LANES) {
      for (std::size_t l = 0; l < LANES; ++l) {
        depth_buf[l] = table_m[r[u + l] & 0x7FFU];
        u_buf[l] = static_cast<float>(u + l);
      }
      const batch depth = batch::load_aligned(depth_buf);
      const auto ok = depth > batch(0.0F);
      const batch ray_x = (batch::load_aligned(u_buf) - batch(camera.cx)) * batch(inv_fx);
      xsimd::select(ok, ray_x * depth, nan).store_unaligned(out.x.data() + row + u);
      xsimd::select(ok, batch(ray_y) * depth, nan).store_unaligned(out.y.data() + row + u);
      xsimd::select(ok, depth, nan).store_unaligned(out.z.data() + row + u);
      row_count = row_count + xsimd::select(ok, batch(1.0F), batch(0.0F));
    }
    valid += static_cast<std::size_t>(xsimd::hadd(row_count));
    valid += project_row_scalar(r, u, width, ray_y, table_m.data(), camera, out.x.data() + row,
                                out.y.data() + row, out.z.data() + row);
  }
  return valid;
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template std::size_t orthoflow::kernels::detail::DepthProjectionKernel::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, std::span<const std::uint16_t>, std::uint32_t, std::uint32_t,
    std::span<const float, orthoflow::kernels::DISPARITY_TABLE_SIZE>,
    const orthoflow::kernels::DepthCamera&, orthoflow::kernels::PointsSpan) const noexcept;
#endif
