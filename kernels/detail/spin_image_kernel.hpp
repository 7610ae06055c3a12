#pragma once
// The spin-image rule both twins share (kernels/spin_image.hpp): the float neighbour test and the
// double binning, and the declaration of the SIMD functor that finds neighbours a batch at a time
// (body in spin_image.inl, one TU per arch; every unit compiled with -ffp-contract=off).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "kernels/point_cloud.hpp"
#include "kernels/simd_arch.hpp"
#include "kernels/spin_image.hpp"

namespace orthoflow::kernels::detail {

/// One call's constants.
struct SpinSetup {
  std::uint32_t width = 0;  // W
  double bin = 0.0;         // s = R / W / sqrt(2)
  double limit = 0.0;       // W * s: the cylinder's radius and half height
  float radius2 = 0.0F;     // R^2 rounded to float, as PCL's radius search compares
  double angle_cos = 0.0;   // 0: no support-angle test
  std::size_t columns = 0;  // 2W + 1
};

/// The constants of a call with @p p (validated by the caller).
inline SpinSetup make_spin_setup(const SpinImageParams& p) noexcept {
  SpinSetup s;
  s.width = p.image_width;
  const double radius = p.support_length;
  s.bin = radius / p.image_width / std::sqrt(2.0);
  s.limit = s.bin * p.image_width;
  s.radius2 = static_cast<float>(radius * radius);
  s.angle_cos = p.support_angle_cos;
  s.columns = 2 * static_cast<std::size_t>(p.image_width) + 1;
  return s;
}

/// One keypoint: its position and normal.
struct SpinKey {
  float x, y, z;
  float nx, ny, nz;
};

// The shared rule has internal linkage: every unit (the scalar twin's, each architecture's, a
// test's) keeps the copy compiled with its own flags, never another unit's (an inline function's
// one definition could otherwise be the AVX-512 unit's, or one with fused multiply-adds).
namespace {

/// Adds the four bilinear weights of cell (@p alpha_bin, @p beta_bin) to @p acc.
inline void spin_scatter(const SpinSetup& s, double* acc, int alpha_bin, int beta_bin, double w00,
                         double w10, double w01, double w11) noexcept {
  double* row = acc + static_cast<std::size_t>(alpha_bin) * s.columns;
  const auto j = static_cast<std::size_t>(beta_bin);
  row[j] += w00;
  row[s.columns + j] += w10;
  row[j + 1] += w01;
  row[s.columns + j + 1] += w11;
}

/// False when neighbour @p p's normal is too far from the keypoint's (the support angle; PCL's
/// rule: |cos| below angle_cos, a NaN cosine taken as 1).
inline bool spin_angle_ok(const SpinSetup& s, const SpinKey& k, PointsView normals,
                          std::size_t p) noexcept {
  if (s.angle_cos <= 0.0) return true;
  const float nn = k.nx * normals.x[p] + k.ny * normals.y[p] + k.nz * normals.z[p];
  double c = static_cast<double>(nn);
  c = std::max(-1.0, std::min(1.0, c));  // NaN becomes 1, as in PCL
  return !(std::abs(c) < s.angle_cos);
}

/// Adds a neighbour at |d| = @p norm with d . n = @p dot (both float) to @p acc: PCL's rule.
inline void spin_bin(const SpinSetup& s, float norm, float dot, double* acc) noexcept {
  const auto dn = static_cast<double>(norm);
  if (std::abs(dn) < 10 * std::numeric_limits<double>::epsilon()) return;  // the keypoint itself
  double c = static_cast<double>(dot) / dn;
  c = std::max(-1.0, std::min(1.0, c));
  double beta = dn * c;
  double alpha = dn * std::sqrt(1.0 - c * c);
  if (std::abs(beta) >= s.limit || alpha >= s.limit) return;  // outside the cylinder
  const auto w = static_cast<int>(s.width);
  int beta_bin = static_cast<int>(std::floor(beta / s.bin)) + w;
  int alpha_bin = static_cast<int>(std::floor(alpha / s.bin));
  if (alpha_bin == w) {  // on the border: the last cell, a just below 1
    --alpha_bin;
    alpha = s.bin * (alpha_bin + 1) - std::numeric_limits<double>::epsilon();
  }
  if (beta_bin == 2 * w) {
    --beta_bin;
    beta = s.bin * (beta_bin - w + 1) - std::numeric_limits<double>::epsilon();
  }
  if (alpha_bin < 0 || beta_bin < 0) return;  // unreachable for finite input; never write outside
  const double a = alpha / s.bin - static_cast<double>(alpha_bin);
  const double b = beta / s.bin - static_cast<double>(beta_bin - w);
  spin_scatter(s, acc, alpha_bin, beta_bin, (1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b);
}

/// The scalar neighbour test for points [begin, end): the operation order the SIMD body uses.
/// @return the neighbours found (within R, the keypoint included).
inline std::size_t spin_range(const SpinSetup& s, const SpinKey& k, PointsView points,
                              PointsView normals, std::size_t begin, std::size_t end,
                              double* acc) noexcept {
  std::size_t found = 0;
  for (std::size_t p = begin; p < end; ++p) {
    const float dx = points.x[p] - k.x;
    const float dy = points.y[p] - k.y;
    const float dz = points.z[p] - k.z;
    const float d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 < s.radius2)) continue;  // NaN is never a neighbour
    ++found;
    if (!spin_angle_ok(s, k, normals, p)) continue;
    const float dot = dx * k.nx + dy * k.ny + dz * k.nz;
    spin_bin(s, std::sqrt(d2), dot, acc);
  }
  return found;
}

}  // namespace

struct SpinNeighboursKernel {
  template <class Arch>
  std::size_t operator()(Arch arch, const SpinSetup& s, const SpinKey& k, PointsView points,
                         PointsView normals, double* acc) const noexcept;
};

}  // namespace orthoflow::kernels::detail
