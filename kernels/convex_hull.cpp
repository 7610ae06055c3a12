#include "kernels/convex_hull.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::kernels {

PlaneBasis make_plane_basis(const Plane& plane) noexcept {
  PlaneBasis b;
  const std::array<double, 3> n{plane.normal[0], plane.normal[1], plane.normal[2]};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  b.n = {n[0] / len, n[1] / len, n[2] / len};
  // Seed axis: the world axis with the smallest |component| of n (never parallel to n).
  std::size_t k = 0;
  for (std::size_t a = 1; a < 3; ++a) { k = std::fabs(b.n[a]) < std::fabs(b.n[k]) ? a : k; }
  std::array<double, 3> e{};
  e[k] = 1.0;
  // u = normalize(e - (e.n) n), v = n x u.
  const double en = b.n[k];
  std::array<double, 3> u{e[0] - en * b.n[0], e[1] - en * b.n[1], e[2] - en * b.n[2]};
  const double ul = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  b.u = {u[0] / ul, u[1] / ul, u[2] / ul};
  b.v = {b.n[1] * b.u[2] - b.n[2] * b.u[1], b.n[2] * b.u[0] - b.n[0] * b.u[2],
         b.n[0] * b.u[1] - b.n[1] * b.u[0]};
  const double d = static_cast<double>(plane.d) / len;
  b.origin = {-d * b.n[0], -d * b.n[1], -d * b.n[2]};
  return b;
}

std::size_t project_to_plane(PointsView points, std::span<const std::uint32_t> indices,
                             const PlaneBasis& b, std::span<double> u,
                             std::span<double> v) noexcept {
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const std::uint32_t i = indices[k];
    const double q[3] = {points.x[i] - b.origin[0], points.y[i] - b.origin[1],
                         points.z[i] - b.origin[2]};
    u[k] = q[0] * b.u[0] + q[1] * b.u[1] + q[2] * b.u[2];
    v[k] = q[0] * b.v[0] + q[1] * b.v[1] + q[2] * b.v[2];
  }
  return indices.size();
}

namespace {

double cross(std::span<const double> u, std::span<const double> v, std::uint32_t o, std::uint32_t a,
             std::uint32_t b) {
  return (u[a] - u[o]) * (v[b] - v[o]) - (v[a] - v[o]) * (u[b] - u[o]);
}

/// Indices of the extreme points along u, v, u+v, u-v and their negations (counter-clockwise from
/// +u; the first index wins ties). Each direction's best score is kept, not recomputed per point.
/// @return false when no point is finite.
bool octagon_extremes(std::span<const double> u, std::span<const double> v,
                      std::array<std::uint32_t, 8>& ext) {
  constexpr double DU[8] = {1, 1, 0, -1, -1, -1, 0, 1};
  constexpr double DV[8] = {0, 1, 1, 1, 0, -1, -1, -1};
  std::array<double, 8> best{};
  bool any = false;
  for (std::uint32_t i = 0; i < u.size(); ++i) {
    if (!std::isfinite(u[i]) || !std::isfinite(v[i])) { continue; }
    for (std::size_t dir = 0; dir < 8; ++dir) {
      const double s = DU[dir] * u[i] + DV[dir] * v[i];
      if (!any || s > best[dir]) { ext[dir] = i, best[dir] = s; }
    }
    any = true;
  }
  return any;
}

/// Akl-Toussaint: drops the points strictly inside the octagon of the extremes (they cannot be hull
/// vertices). Keeps the rest in index order in @p keep; returns how many. The proper edges' origins
/// and directions are computed once; a repeated edge stands in for a degenerate one (same verdict),
/// so each point is tested against exactly 8 edges without a branch per edge.
std::size_t octagon_filter(std::span<const double> u, std::span<const double> v,
                           std::span<std::uint32_t> keep) {
  std::array<std::uint32_t, 8> ext{};
  if (!octagon_extremes(u, v, ext)) { return 0; }
  std::array<double, 8> au{}, av{}, du{}, dv{};
  std::size_t edges = 0;
  for (std::size_t e = 0; e < 8; ++e) {
    const std::uint32_t a = ext[e], b = ext[(e + 1) % 8];
    if (a == b) { continue; }
    au[edges] = u[a], av[edges] = v[a], du[edges] = u[b] - u[a], dv[edges] = v[b] - v[a];
    ++edges;
  }
  // With no proper edge (all points equal) nothing is interior: a zero edge gives cross 0, not > 0.
  for (std::size_t e = edges; e < 8; ++e) {
    const std::size_t src = edges == 0 ? 0 : e % edges;
    au[e] = au[src], av[e] = av[src], du[e] = du[src], dv[e] = dv[src];
  }
  std::size_t m = 0;
  for (std::uint32_t i = 0; i < u.size(); ++i) {
    // Strictly left of every octagon edge (counter-clockwise) means interior; the same products as
    // cross(a, b, i) so the verdict is unchanged. NaN gives false, i.e. not interior: skipped
    // below.
    unsigned left = 0;
    for (std::size_t e = 0; e < 8; ++e) {
      left += du[e] * (v[i] - av[e]) - dv[e] * (u[i] - au[e]) > 0.0 ? 1U : 0U;
    }
    if (left == 8 || !std::isfinite(u[i]) || !std::isfinite(v[i])) { continue; }
    keep[m++] = i;
  }
  return m;
}

}  // namespace

std::size_t convex_hull_2d(std::span<const double> u, std::span<const double> v,
                           std::span<std::uint32_t> scratch,
                           std::span<std::uint32_t> hull_out) noexcept {
  const std::size_t m = octagon_filter(u, v, scratch);
  std::uint32_t* pts = scratch.data();
  std::sort(pts, pts + m, [&](std::uint32_t a, std::uint32_t b) {
    return u[a] != u[b] ? u[a] < u[b] : (v[a] != v[b] ? v[a] < v[b] : a < b);
  });
  // Drop exact duplicates (keep the lowest index) so that they never become two vertices.
  const auto unique_end = std::unique(
      pts, pts + m, [&](std::uint32_t a, std::uint32_t b) { return u[a] == u[b] && v[a] == v[b]; });
  const auto count = static_cast<std::size_t>(unique_end - pts);
  if (count < 3) {
    std::copy(pts, pts + count, hull_out.begin());
    return count;
  }
  std::size_t k = 0;
  // Lower chain then upper chain; cross <= 0 pops collinear points too.
  for (std::size_t i = 0; i < count; ++i) {
    while (k >= 2 && cross(u, v, hull_out[k - 2], hull_out[k - 1], pts[i]) <= 0.0) { --k; }
    hull_out[k++] = pts[i];
  }
  for (std::size_t i = count - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(u, v, hull_out[k - 2], hull_out[k - 1], pts[i]) <= 0.0) { --k; }
    hull_out[k++] = pts[i];
  }
  const std::size_t size = k - 1;  // the last vertex repeats the first
  return size < 3 ? std::min<std::size_t>(size, 2) : size;
}

}  // namespace orthoflow::kernels
