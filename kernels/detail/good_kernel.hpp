#pragma once
// Declarations of the two GOOD SIMD functors (bodies in good_bins.inl, one TU per arch) and the
// scalar per-point rules shared by compute_good_scalar() and the SIMD tails, so both apply the same
// arithmetic.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/point_cloud.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

/// Rigid map q = R (p - c) in float; rows of R are the frame axes (signs already applied).
struct GoodTransform {
  std::array<float, 3> c{};
  std::array<std::array<float, 3>, 3> r{};
};

/// Pass 1 output: AABB of q and the sign counts along X and Y (strictly beyond +-t).
struct GoodStats {
  std::array<float, 3> min{};
  std::array<float, 3> max{};
  std::array<std::size_t, 2> pos{};
  std::array<std::size_t, 2> neg{};
};

/// Pass 2 parameters: bin of a coordinate a is trunc((a + half) / width), kept if in (-1, bins).
struct GoodBinParams {
  GoodTransform t;
  float half = 0.0F;
  float width = 1.0F;
  std::size_t bins = 1;
};

struct GoodStatsKernel {
  template <class Arch>
  GoodStats operator()(Arch arch, PointsView points, const GoodTransform& t,
                       float threshold) const noexcept;
};

struct GoodBinKernel {
  /// Adds to counts (3 n^2 + 3: the views in canonical order, then one slot per view counting the
  /// points it dropped), zeroed by the caller.
  template <class Arch>
  void operator()(Arch arch, PointsView points, const GoodBinParams& p,
                  std::span<std::uint32_t> counts) const noexcept;
};

inline std::array<float, 3> good_transform_point(const GoodTransform& t, float x, float y,
                                                 float z) noexcept {
  const float dx = x - t.c[0];
  const float dy = y - t.c[1];
  const float dz = z - t.c[2];
  std::array<float, 3> q{};
  for (std::size_t a = 0; a < 3; ++a) {
    const float xy = t.r[a][0] * dx + t.r[a][1] * dy;  // grouped exactly as the SIMD body
    q[a] = xy + t.r[a][2] * dz;
  }
  return q;
}

/// Pass 1 rule for points [begin, end).
inline void good_stats_scalar(PointsView points, const GoodTransform& t, float threshold,
                              std::size_t begin, std::size_t end, GoodStats& s) noexcept {
  for (std::size_t i = begin; i < end; ++i) {
    if (!std::isfinite(points.x[i]) || !std::isfinite(points.y[i]) || !std::isfinite(points.z[i])) {
      continue;
    }
    const std::array<float, 3> q = good_transform_point(t, points.x[i], points.y[i], points.z[i]);
    for (std::size_t a = 0; a < 3; ++a) {
      s.min[a] = std::min(s.min[a], q[a]);
      s.max[a] = std::max(s.max[a], q[a]);
    }
    for (std::size_t a = 0; a < 2; ++a) {
      s.pos[a] += q[a] > threshold ? 1U : 0U;
      s.neg[a] += q[a] < -threshold ? 1U : 0U;
    }
  }
}

/// Bin of one coordinate, or -1 when the reference would drop it (u/w <= -1, >= n, or NaN).
/// trunc() sends (-1, 0) to bin 0, as the reference does (GOOD_REFERENCE.md section 5).
inline int good_bin_scalar(float a, const GoodBinParams& p) noexcept {
  const float f = (a + p.half) / p.width;
  if (!(f > -1.0F) || !(f < static_cast<float>(p.bins))) { return -1; }
  return static_cast<int>(f);
}

/// Slot of one view's cell (row, col), or the view's drop slot 3 n^2 + view when either is -1.
inline std::size_t good_slot(int row, int col, std::size_t view, std::size_t n) noexcept {
  if (row < 0 || col < 0) { return 3 * n * n + view; }
  return view * n * n + static_cast<std::size_t>(row) * n + static_cast<std::size_t>(col);
}

/// Adds one point's three bins (canonical views: YoZ = (y, z), XoZ = (x, z), XoY = (x, y)).
inline void good_add_bins(int kx, int ky, int kz, std::size_t n,
                          std::span<std::uint32_t> counts) noexcept {
  ++counts[good_slot(ky, kz, 0, n)];
  ++counts[good_slot(kx, kz, 1, n)];
  ++counts[good_slot(kx, ky, 2, n)];
}

/// Pass 2 rule for points [begin, end).
inline void good_bin_range_scalar(PointsView points, const GoodBinParams& p, std::size_t begin,
                                  std::size_t end, std::span<std::uint32_t> counts) noexcept {
  for (std::size_t i = begin; i < end; ++i) {
    const std::array<float, 3> q = good_transform_point(p.t, points.x[i], points.y[i], points.z[i]);
    good_add_bins(good_bin_scalar(q[0], p), good_bin_scalar(q[1], p), good_bin_scalar(q[2], p),
                  p.bins, counts);
  }
}

}  // namespace orthoflow::kernels::detail
