#include "kernels/euclidean_cluster.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

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

/// Union-find over scratch.parent: the root is the component's lowest index (deterministic).
struct Forest {
  std::uint32_t* parent;
  std::uint32_t find(std::uint32_t i) const noexcept {
    while (parent[i] != i) {
      parent[i] = parent[parent[i]];  // path halving
      i = parent[i];
    }
    return i;
  }
  void unite(std::uint32_t a, std::uint32_t b) const noexcept {
    a = find(a);
    b = find(b);
    if (a != b) { parent[std::max(a, b)] = std::min(a, b); }
  }
};

bool included(PointsView p, std::span<const std::uint8_t> mask, std::size_t i) {
  return (mask.empty() || mask[i] != 0) && std::isfinite(p.x[i]) && std::isfinite(p.y[i]) &&
         std::isfinite(p.z[i]);
}

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

/// assign_labels() for the ascending list of the included points: touches only them (and clears
/// labels).
std::size_t assign_labels_listed(std::span<const std::uint32_t> members, const ClusterParams& prm,
                                 ClusterScratch& s, std::span<std::int32_t> labels) {
  const Forest forest{s.parent.data()};
  for (const std::uint32_t i : members) { s.count[i] = 0; }
  for (const std::uint32_t i :
       members) {  // no link follows: each member can point at its root directly
    s.parent[i] = forest.find(i);
    ++s.count[s.parent[i]];
  }
  std::int32_t next = 0;
  std::size_t cleared =
      0;  // labels[0, cleared) are written: the gaps between members get -1 on the way
  for (const std::uint32_t i :
       members) {  // ascending: a component's root comes before its other points
    std::fill(labels.begin() + static_cast<std::ptrdiff_t>(cleared), labels.begin() + i, -1);
    cleared = std::size_t{i} + 1;
    const std::uint32_t root = s.parent[i];
    if (root == i) {
      const bool keep = s.count[i] >= prm.min_size && s.count[i] <= prm.max_size;
      s.count[i] = keep ? static_cast<std::uint32_t>(++next) : 0U;
    }
    labels[i] = static_cast<std::int32_t>(s.count[root]) - 1;
  }
  std::fill(labels.begin() + static_cast<std::ptrdiff_t>(cleared), labels.end(), -1);
  return static_cast<std::size_t>(next);
}

Result<std::size_t, ClusterError> check(std::size_t n, const ClusterParams& prm,
                                        const ClusterScratch& s) {
  using Code = ClusterError::Code;
  if (!std::isfinite(prm.tolerance) || !(prm.tolerance > 0.0F)) {
    return err(ClusterError{Code::BAD_PARAMS, prm.tolerance});
  }
  if (prm.min_size > prm.max_size) {
    return err(ClusterError{Code::BAD_PARAMS, double(prm.min_size)});
  }
  if (prm.pixel_radius == 0) { return err(ClusterError{Code::BAD_PARAMS, 0.0}); }
  if (n > s.capacity()) { return err(ClusterError{Code::SCRATCH_TOO_SMALL, double(n)}); }
  return n;
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

constexpr std::uint32_t NOT_INCLUDED = 0xFFFFFFFFU;  // parent[] of a pixel that takes no part

/// Links pixel i (at xi, yi, zi) to its neighbours one at a time, keeping i's current root. A
/// neighbour whose parent already is that root is in i's component: no distance test, no find().
/// clean stays true while every included neighbour seen is known to end in i's component.
struct Linker {
  PointsView p;
  std::uint32_t* parent;
  float tol2, xi, yi, zi;
  std::uint32_t root;
  bool clean = true;
  void visit(std::size_t j) noexcept {
    const std::uint32_t pj = parent[j];
    if (pj == NOT_INCLUDED || pj == root) { return; }
    const float dx = xi - p.x[j], dy = yi - p.y[j], dz = zi - p.z[j];
    if (dx * dx + dy * dy + dz * dz > tol2) {
      clean = false;  // maybe in another component: not known
      return;
    }
    const std::uint32_t other = Forest{parent}.find(static_cast<std::uint32_t>(j));
    if (other == root) { return; }
    parent[std::max(root, other)] =
        std::min(root, other);  // roots: the lowest index stays the root
    root = std::min(root, other);
  }
};

/// Links pixel i = (u, v) to the backward half of its (2r+1)^2 window (the r pixels before it in
/// its row, then the r rows above), already linked among themselves: every edge of the window graph
/// is seen from its later pixel. Row runs: when the left pixel i-1 is included, was clean (every
/// included pixel of its window ended in its component) and links to i, the part of i's window that
/// i-1's window covers is in i's component already, so only the new column u + r of the rows above
/// is visited (the partition is the same, far fewer edges are tested). @return whether i is clean.
bool link_window(PointsView p, std::size_t w, std::size_t u, std::size_t v,
                 const ClusterParams& prm, std::uint32_t* parent, bool left_clean) {
  const std::size_t r = prm.pixel_radius, i = v * w + u;
  const std::size_t u_lo = u >= r ? u - r : 0, u_hi = std::min(w - 1, u + r),
                    v_lo = v >= r ? v - r : 0;
  Linker link{p,      parent, prm.tolerance * prm.tolerance, p.x[i],
              p.y[i], p.z[i], static_cast<std::uint32_t>(i)};
  if (left_clean) {
    link.visit(i - 1);
    if (link.root != i) {  // i joined i-1's component
      for (std::size_t vv = v_lo; vv < v && u + r < w; ++vv) { link.visit(vv * w + u + r); }
      parent[i] = link.root;
      return link.clean;
    }
  }
  for (std::size_t vv = v_lo; vv <= v; ++vv) {
    const std::size_t end = vv == v ? u : u_hi + 1;
    for (std::size_t uu = u_lo; uu < end; ++uu) { link.visit(vv * w + uu); }
  }
  parent[i] = link.root;  // path compression: later windows then mostly see the root directly
  return link.clean;
}

/// Lists the included points in ascending order (scratch.order) and makes each its own root; every
/// other parent is NOT_INCLUDED, so a window reads one word per neighbour. One pass writes every
/// parent (no separate fill of the frame). Most of a frame is masked out: eight zero mask bytes are
/// one 64-bit test and eight stores. @return the number listed.
std::size_t list_members(PointsView p, std::span<const std::uint8_t> mask, ClusterScratch& s) {
  std::uint32_t* parent = s.parent.data();
  const std::size_t n = p.size();
  std::size_t m = 0;
  for (std::size_t i = 0; i < n;) {
    if (!mask.empty() && i + 8 <= n) {
      std::uint64_t word = 0;
      std::memcpy(&word, mask.data() + i, sizeof word);
      if (word == 0) {
        for (std::size_t k = 0; k < 8; ++k) { parent[i + k] = NOT_INCLUDED; }
        i += 8;
        continue;
      }
    }
    const bool in = included(p, mask, i);
    parent[i] = in ? static_cast<std::uint32_t>(i) : NOT_INCLUDED;
    if (in) { s.order[m++] = static_cast<std::uint32_t>(i); }
    ++i;
  }
  return m;
}

}  // namespace

Result<std::size_t, ClusterError> euclidean_cluster_organized(
    CloudView cloud, std::span<const std::uint8_t> mask, const ClusterParams& params,
    ClusterScratch& scratch, std::span<std::int32_t> labels) noexcept {
  const PointsView p = cloud.points;
  scratch.listed = 0;
  if (auto ok = check(p.size(), params, scratch); !ok) { return ok; }
  const std::size_t m = list_members(p, mask, scratch);
  scratch.listed = m;
  const auto members = std::span<const std::uint32_t>(scratch.order).first(m);
  const auto w = static_cast<std::size_t>(cloud.width);
  std::size_t v = 0, row_start = 0, previous = 0;
  bool previous_clean = false;
  for (const std::uint32_t i : members) {
    while (i >= row_start + w) {
      ++v, row_start += w;
    }  // rows from the ascending list: no division
    const bool left_clean = previous_clean && previous + 1 == i && i > row_start;
    previous_clean = link_window(p, w, i - row_start, v, params, scratch.parent.data(), left_clean);
    previous = i;
  }
  return assign_labels_listed(members, params, scratch, labels.first(p.size()));
}

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
