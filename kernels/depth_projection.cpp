#include "kernels/depth_projection.hpp"

#include "core/assert.hpp"
#include "kernels/detail/depth_projection_kernel.hpp"

namespace orthoflow::kernels {

void fill_disparity_table_reciprocal(std::span<float, DISPARITY_TABLE_SIZE> table_m) noexcept {
  // KINECT_V1.md 8.1: the fit has its pole near raw = 1084.6, so stop at 1080 (about 9.6 m).
  for (std::size_t raw = 0; raw < DISPARITY_TABLE_SIZE; ++raw) {
    const double denom = static_cast<double>(raw) * -0.0030711016 + 3.3309495161;
    table_m[raw] = raw < 1080 ? static_cast<float>(1.0 / denom) : 0.0F;
  }
}

std::size_t depth_to_points_scalar(std::span<const std::uint16_t> raw, std::uint32_t width,
                                   std::uint32_t height,
                                   std::span<const float, DISPARITY_TABLE_SIZE> table_m,
                                   const DepthCamera& camera, PointsSpan out) noexcept {
  OF_ASSERT(raw.size() == std::size_t{width} * height && out.size() == raw.size(),
            "depth_to_points: size mismatch");
  const float inv_fy = 1.0F / camera.fy;
  std::size_t valid = 0;
  for (std::size_t v = 0; v < height; ++v) {
    const std::size_t row = v * width;
    const float ray_y = (static_cast<float>(v) - camera.cy) * inv_fy;
    valid += detail::project_row_scalar(raw.data() + row, 0, width, ray_y, table_m.data(), camera,
                                        out.x.data() + row, out.y.data() + row, out.z.data() + row);
  }
  return valid;
}

std::size_t depth_to_points(std::span<const std::uint16_t> raw, std::uint32_t width,
                            std::uint32_t height,
                            std::span<const float, DISPARITY_TABLE_SIZE> table_m,
                            const DepthCamera& camera, PointsSpan out) noexcept {
  OF_ASSERT(raw.size() == std::size_t{width} * height && out.size() == raw.size(),
            "depth_to_points: size mismatch");
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::DepthProjectionKernel{});
  return dispatched(raw, width, height, table_m, camera, out);
}

}  // namespace orthoflow::kernels
