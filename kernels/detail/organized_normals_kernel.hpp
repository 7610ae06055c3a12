#pragma once
// Declaration of the organized-normals SIMD functor (body in organized_normals.inl, one TU per
// arch) and the scalar rule the twin and the SIMD tails share.
#include <cmath>
#include <limits>

#include "kernels/organized_normals.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

struct OrganizedNormalsRowKernel {
  /// Columns [begin, end) of row r (every neighbour inside the image), returns normals written.
  template <class Arch>
  std::size_t operator()(Arch arch, CloudView cloud, const NormalParams& params, std::size_t r,
                         std::size_t begin, std::size_t end, PointsSpan out) const noexcept;
};

inline void set_nan(PointsSpan out, std::size_t i) noexcept {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  out.x[i] = nan, out.y[i] = nan, out.z[i] = nan;
}

/// The last step of the rule, scalar in both twins (xsimd's NEON float sqrt and division are
/// estimates, not IEEE): the unnormalised normal (nx, ny, nz) of pixel i, turned toward the sensor
/// and normalised, or NaN. @return true when written as a normal.
inline bool finish_normal(PointsView p, std::size_t i, float nx, float ny, float nz,
                          PointsSpan out) noexcept {
  const float len = std::sqrt(nx * nx + ny * ny + nz * nz);
  const float facing = nx * p.x[i] + ny * p.y[i] + nz * p.z[i];
  const float scale = (facing > 0.0F ? -1.0F : 1.0F) / len;
  nx *= scale, ny *= scale, nz *= scale;
  if (len > 0.0F && std::isfinite(nx) && std::isfinite(ny) && std::isfinite(nz)) {
    out.x[i] = nx, out.y[i] = ny, out.z[i] = nz;
    return true;
  }
  set_nan(out, i);
  return false;
}

/// The scalar rule for pixels [begin, end) of row r, all of whose neighbours lie in the image.
inline std::size_t normals_range(CloudView cloud, const NormalParams& prm, std::size_t r,
                                 std::size_t begin, std::size_t end, PointsSpan out) noexcept {
  const PointsView p = cloud.points;
  const std::size_t w = cloud.width, s = prm.offset;
  std::size_t written = 0;
  for (std::size_t c = begin; c < end; ++c) {
    const std::size_t i = r * w + c;
    const std::size_t up = i - s * w, down = i + s * w, left = i - s, right = i + s;
    const float z = p.z[i];
    const float limit = prm.depth_change * z;
    const bool ok = std::fabs(p.z[up] - z) <= limit && std::fabs(p.z[down] - z) <= limit &&
                    std::fabs(p.z[left] - z) <= limit && std::fabs(p.z[right] - z) <= limit;
    // v = down - up, h = right - left, n = v x h
    const float vx = p.x[down] - p.x[up], vy = p.y[down] - p.y[up], vz = p.z[down] - p.z[up];
    const float hx = p.x[right] - p.x[left], hy = p.y[right] - p.y[left],
                hz = p.z[right] - p.z[left];
    const float nx = vy * hz - vz * hy, ny = vz * hx - vx * hz, nz = vx * hy - vy * hx;
    if (ok) {
      written += finish_normal(p, i, nx, ny, nz, out) ? 1U : 0U;
    } else {
      set_nan(out, i);
    }
  }
  return written;
}

}  // namespace orthoflow::kernels::detail
