#include "kernels/pixel_subsample.hpp"

#include <cmath>

#include "core/assert.hpp"

namespace orthoflow::kernels {

std::size_t pixel_subsample(CloudView cloud, std::uint32_t stride, const AxisBox& roi,
                            PointsSpan out) noexcept {
  OF_ASSERT(stride >= 1, "pixel_subsample: stride 0");
  OF_ASSERT(cloud.points.size() == std::size_t{cloud.width} * cloud.height,
            "pixel_subsample: not width x height");
  const PointsView p = cloud.points;
  std::size_t written = 0;
  for (std::size_t v = stride / 2; v < cloud.height; v += stride) {
    for (std::size_t u = stride / 2; u < cloud.width; u += stride) {
      const std::size_t i = v * cloud.width + u;
      const float x = p.x[i], y = p.y[i], z = p.z[i];
      // crop_box_mask's rule (NaN fails every comparison), plus finiteness for boxes with infinite
      // bounds.
      const bool keep = x >= roi.min[0] && x <= roi.max[0] && y >= roi.min[1] && y <= roi.max[1] &&
                        z >= roi.min[2] && z <= roi.max[2] && std::isfinite(x) &&
                        std::isfinite(y) && std::isfinite(z);
      if (!keep) { continue; }
      OF_ASSERT(written < out.size(), "pixel_subsample: output too small");
      out.x[written] = x;
      out.y[written] = y;
      out.z[written] = z;
      ++written;
    }
  }
  return written;
}

}  // namespace orthoflow::kernels
