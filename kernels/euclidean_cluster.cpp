// Euclidean clustering of any cloud with a sorted spatial grid (kernels/euclidean_cluster.hpp):
// cells of side tolerance, each linked to its 13 forward neighbours. Also ClusterError's message.
// The image-space window of organized clouds is in euclidean_cluster_organized.cpp.
#include "kernels/euclidean_cluster.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "kernels/detail/cluster_forest.hpp"
#include "kernels/detail/number_text.hpp"
#include "kernels/detail/radix_sort.hpp"

namespace orthoflow::kernels {

std::string ClusterError::to_string() const {
  switch (code) {
    case Code::BAD_PARAMS:
      return "euclidean_cluster: invalid parameter value " + detail::value_text(value);
    case Code::SCRATCH_TOO_SMALL:
      return "euclidean_cluster: scratch too small for " + detail::count_text(value) + " points";
    case Code::GRID_OVERFLOW:
      return "euclidean_cluster: extent/tolerance " + detail::value_text(value) +
             " overflows the 64-bit cell key";
  }
  return "euclidean_cluster: unknown error";
}

namespace {

using detail::check;
using detail::Forest;
using detail::included;

bool near(PointsView p, std::size_t a, std::size_t b, float tol2) {
  const float dx = p.x[a] - p.x[b], dy = p.y[a] - p.y[b], dz = p.z[a] - p.z[b];
  return dx * dx + dy * dy + dz * dz <= tol2;
}

/// Sizes the components, keeps those within [min_size, max_size], numbers them by lowest index.
/// incl(i) tells whether point i takes part (the union-find only linked such points).
template <class Included>
std::size_t assign_labels(std::size_t n, Included incl, const ClusterParams& prm, ClusterScratch& s,
                          std::span<std::int32_t> labels) {
  const Forest forest{s.parent.data()};
  std::fill(s.count.begin(), s.count.begin() + static_cast<std::ptrdiff_t>(n), 0U);
  for (std::size_t i = 0; i < n; ++i) {
    if (incl(i)) { ++s.count[forest.find(static_cast<std::uint32_t>(i))]; }
  }
  std::int32_t next = 0;
  for (std::size_t i = 0; i < n; ++i) {
    labels[i] = -1;
    if (!incl(i)) { continue; }
    const std::uint32_t root = forest.find(static_cast<std::uint32_t>(i));
    if (root == i) {  // first point of its component: count[] is reused to hold the label + 1
      const bool keep = s.count[i] >= prm.min_size && s.count[i] <= prm.max_size;
      s.count[i] = keep ? static_cast<std::uint32_t>(++next) : 0U;
    }
    labels[i] = static_cast<std::int32_t>(s.count[root]) - 1;
  }
  return static_cast<std::size_t>(next);
}

/// Cell key layout of the grid: cells of side tolerance, indices shifted by one so that every
/// neighbour of an occupied cell has a valid key; key = ix + nx * (iy + ny * iz).
struct Grid {
  std::array<double, 3> lo{};
  std::uint64_t nx = 0, ny = 0;
  double inv = 0.0;
  std::size_t cells = 0;  // occupied cells
};

/// Sorts the included points by cell (scratch.order) and lists the occupied cells (keys,
/// cell_start).
Result<Grid, ClusterError> build_grid(PointsView p, std::span<const std::uint8_t> mask, float tol,
                                      ClusterScratch& s) {
  Grid g;
  g.inv = 1.0 / static_cast<double>(tol);
  std::array<double, 3> hi{};
  std::size_t m = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!included(p, mask, i)) { continue; }
    const double c[3] = {p.x[i], p.y[i], p.z[i]};
    for (std::size_t a = 0; a < 3; ++a) {
      g.lo[a] = m == 0 ? c[a] : std::min(g.lo[a], c[a]);
      hi[a] = m == 0 ? c[a] : std::max(hi[a], c[a]);
    }
    s.order[m++] = static_cast<std::uint32_t>(i);
  }
  if (m == 0) { return g; }
  std::array<double, 3> ext{};
  for (std::size_t a = 0; a < 3; ++a) { ext[a] = std::floor((hi[a] - g.lo[a]) * g.inv) + 3.0; }
  if (!(ext[0] * ext[1] * ext[2] < 1.8e19)) {
    return err(ClusterError{ClusterError::Code::GRID_OVERFLOW, ext[0] * ext[1] * ext[2]});
  }
  g.nx = static_cast<std::uint64_t>(ext[0]);
  g.ny = static_cast<std::uint64_t>(ext[1]);
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint32_t i = s.order[k];
    const auto ix =
        static_cast<std::uint64_t>((p.x[i] - g.lo[0]) * g.inv) + 1U;  // >= 0: cast floors
    const auto iy =
        static_cast<std::uint64_t>((p.y[i] - g.lo[1]) * g.inv) + 1U;  // >= 0: cast floors
    const auto iz =
        static_cast<std::uint64_t>((p.z[i] - g.lo[2]) * g.inv) + 1U;  // >= 0: cast floors
    s.keys[k] = ix + g.nx * (iy + g.ny * iz);
  }
  const auto max_key = static_cast<std::uint64_t>(ext[0] * ext[1] * ext[2]);
  if (detail::radix_sort_pairs(s.keys.data(), s.keys_tmp.data(), s.order.data(), s.order_tmp.data(),
                               m, max_key)) {
    std::copy(s.keys_tmp.begin(), s.keys_tmp.begin() + static_cast<std::ptrdiff_t>(m),
              s.keys.begin());
    std::copy(s.order_tmp.begin(), s.order_tmp.begin() + static_cast<std::ptrdiff_t>(m),
              s.order.begin());
  }
  // Compact the sorted keys to one per cell (keys_tmp) with the start of each cell's run in
  // order[].
  for (std::size_t k = 0; k < m; ++k) {
    if (k == 0 || s.keys[k] != s.keys[k - 1]) {
      s.keys_tmp[g.cells] = s.keys[k];
      s.cell_start[g.cells++] = static_cast<std::uint32_t>(k);
    }
  }
  s.cell_start[g.cells] = static_cast<std::uint32_t>(m);
  return g;
}

/// Links every pair within tolerance between cell c and its 13 forward neighbours and itself.
void link_cells(PointsView p, const Grid& g, float tol2, ClusterScratch& s) {
  const Forest forest{s.parent.data()};
  const std::uint64_t* cell_keys = s.keys_tmp.data();
  for (std::size_t c = 0; c < g.cells; ++c) {
    for (int dz = 0; dz <= 1; ++dz) {
      for (int dy = dz == 0 ? 0 : -1; dy <= 1; ++dy) {
        for (int dx = (dz == 0 && dy == 0) ? 0 : -1; dx <= 1; ++dx) {
          const std::uint64_t key =
              cell_keys[c] + static_cast<std::uint64_t>(dx) +
              g.nx * (static_cast<std::uint64_t>(dy) + g.ny * static_cast<std::uint64_t>(dz));
          const std::uint64_t* hit = std::lower_bound(cell_keys + c, cell_keys + g.cells, key);
          if (hit == cell_keys + g.cells || *hit != key) { continue; }
          const auto nc = static_cast<std::size_t>(hit - cell_keys);
          for (std::uint32_t a = s.cell_start[c]; a < s.cell_start[c + 1]; ++a) {
            for (std::uint32_t b = nc == c ? a + 1 : s.cell_start[nc]; b < s.cell_start[nc + 1];
                 ++b) {
              const std::uint32_t i = s.order[a], j = s.order[b];
              if (near(p, i, j, tol2) && forest.find(i) != forest.find(j)) { forest.unite(i, j); }
            }
          }
        }
      }
    }
  }
}

}  // namespace

Result<std::size_t, ClusterError> euclidean_cluster(PointsView points,
                                                    std::span<const std::uint8_t> mask,
                                                    const ClusterParams& params,
                                                    ClusterScratch& scratch,
                                                    std::span<std::int32_t> labels) noexcept {
  if (auto ok = check(points.size(), params, scratch); !ok) { return ok; }
  scratch.listed = 0;  // order[] is reused in cell order below
  for (std::uint32_t i = 0; i < points.size(); ++i) { scratch.parent[i] = i; }
  auto grid_result = build_grid(points, mask, params.tolerance, scratch);
  if (!grid_result) { return err(grid_result.error()); }
  link_cells(points, *grid_result, params.tolerance * params.tolerance, scratch);
  return assign_labels(
      points.size(), [&](std::size_t i) { return included(points, mask, i); }, params, scratch,
      labels);
}

}  // namespace orthoflow::kernels
