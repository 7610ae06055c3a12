#include "kernels/frame_labels.hpp"

#include <cmath>

namespace orthoflow::kernels {

namespace {
bool inside(const AxisBox& box, float x, float y, float z) noexcept {
  return x >= box.min[0] && x <= box.max[0] && y >= box.min[1] && y <= box.max[1] &&
         z >= box.min[2] && z <= box.max[2];  // false for NaN
}
}  // namespace

void frame_labels(PointsView points, const Plane& plane, float table_tau, const AxisBox& roi,
                  std::span<const std::int32_t> cluster_of, std::span<const std::int32_t> slot_of,
                  std::span<std::uint32_t> out) noexcept {
  const auto& n = plane.normal;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::int32_t c = cluster_of[i];
    if (c >= 0 && static_cast<std::size_t>(c) < slot_of.size() &&
        slot_of[static_cast<std::size_t>(c)] >= 0) {
      out[i] =
          FIRST_OBJECT_LABEL + static_cast<std::uint32_t>(slot_of[static_cast<std::size_t>(c)]);
      continue;
    }
    const float x = points.x[i], y = points.y[i], z = points.z[i];
    const float dist = n[0] * x + n[1] * y + n[2] * z + plane.d;
    out[i] = inside(roi, x, y, z) && std::fabs(dist) <= table_tau ? TABLE_LABEL : 0U;
  }
}

}  // namespace orthoflow::kernels
