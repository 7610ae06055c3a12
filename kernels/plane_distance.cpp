#include "kernels/plane_distance.hpp"

#include "core/assert.hpp"
#include "kernels/detail/plane_distance_kernel.hpp"

namespace orthoflow::kernels {

std::size_t count_plane_inliers_scalar(PointsView points, const Plane& plane, float tau) noexcept {
  return detail::count_inliers_range(points, plane, tau, 0, points.size());
}

std::size_t count_plane_inliers(PointsView points, const Plane& plane, float tau) noexcept {
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::PlaneInlierKernel{});
  return dispatched(points, plane, tau);
}

std::size_t plane_signed_distance_scalar(PointsView points, const Plane& plane,
                                         std::span<float> out) noexcept {
  OF_ASSERT(out.size() >= points.size(), "plane_signed_distance: output too small");
  for (std::size_t i = 0; i < points.size(); ++i) {
    out[i] = detail::plane_distance(plane, points.x[i], points.y[i], points.z[i]);
  }
  return points.size();
}

std::size_t plane_signed_distance(PointsView points, const Plane& plane,
                                  std::span<float> out) noexcept {
  OF_ASSERT(out.size() >= points.size(), "plane_signed_distance: output too small");
  static auto dispatched = xsimd::dispatch<SimdArchs>(detail::PlaneDistanceKernel{});
  return dispatched(points, plane, out);
}

}  // namespace orthoflow::kernels
