#pragma once
// Declarations of the capsule-mask SIMD functor and the scalar rule it shares; body in
// capsule_mask.inl (one TU per arch).
#include <algorithm>
#include <cmath>

#include "kernels/capsule_mask.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

/// A capsule prepared once per call: start, direction, 1 / |direction|^2 (0 for a sphere), r^2.
struct PreparedCapsule {
  float ax, ay, az;
  float dx, dy, dz;
  float inv_len2;
  float r2;
};

/// The usable capsules of @p in, prepared into @p out (at most MAX_CAPSULES). @return their count.
inline std::size_t prepare_capsules(std::span<const Capsule> in, PreparedCapsule* out) noexcept {
  std::size_t n = 0;
  for (const Capsule& c : in.first(std::min(in.size(), MAX_CAPSULES))) {
    const bool finite = std::isfinite(c.a[0]) && std::isfinite(c.a[1]) && std::isfinite(c.a[2]) &&
                        std::isfinite(c.b[0]) && std::isfinite(c.b[1]) && std::isfinite(c.b[2]) &&
                        std::isfinite(c.radius);
    if (!finite || c.radius < 0.0F) { continue; }
    PreparedCapsule& p = out[n++];
    p.ax = c.a[0];
    p.ay = c.a[1];
    p.az = c.a[2];
    p.dx = c.b[0] - c.a[0];
    p.dy = c.b[1] - c.a[1];
    p.dz = c.b[2] - c.a[2];
    const float len2 = p.dx * p.dx + p.dy * p.dy + p.dz * p.dz;
    p.inv_len2 = len2 > 0.0F ? 1.0F / len2 : 0.0F;
    p.r2 = c.radius * c.radius;
  }
  return n;
}

/// The squared distance of (x, y, z) to the capsule's segment, in the exact operation order the
/// SIMD body uses.
inline float segment_distance2(const PreparedCapsule& c, float x, float y, float z) noexcept {
  const float px = x - c.ax;
  const float py = y - c.ay;
  const float pz = z - c.az;
  const float dot = px * c.dx + py * c.dy + pz * c.dz;
  const float t = std::min(std::max(dot * c.inv_len2, 0.0F), 1.0F);
  const float ex = px - t * c.dx;
  const float ey = py - t * c.dy;
  const float ez = pz - t * c.dz;
  return ex * ex + ey * ey + ez * ez;
}

/// Scalar rule for points [begin, end) (shared by the twin and the SIMD tail).
inline std::size_t capsule_mask_range(PointsView in, const PreparedCapsule* caps, std::size_t count,
                                      std::uint8_t* mask, std::size_t begin,
                                      std::size_t end) noexcept {
  std::size_t removed = 0;
  for (std::size_t i = begin; i < end; ++i) {
    bool inside = false;
    for (std::size_t k = 0; k < count; ++k) {
      // NaN fails the comparison: a NaN point is never inside.
      inside = inside || segment_distance2(caps[k], in.x[i], in.y[i], in.z[i]) <= caps[k].r2;
    }
    mask[i] = inside ? 0 : 1;
    removed += inside ? 1U : 0U;
  }
  return removed;
}

struct CapsuleMaskKernel {
  template <class Arch>
  std::size_t operator()(Arch arch, PointsView in, const PreparedCapsule* caps, std::size_t count,
                         std::span<std::uint8_t> mask) const noexcept;
};

}  // namespace orthoflow::kernels::detail
