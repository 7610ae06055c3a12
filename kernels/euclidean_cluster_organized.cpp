// Euclidean clustering of an organized cloud in image space (kernels/euclidean_cluster.hpp): each
// included pixel is linked to the backward half of its window, then the components are numbered
// over the ascending list of included pixels only. The spatial grid is in euclidean_cluster.cpp.
#include "kernels/euclidean_cluster.hpp"

#include <algorithm>
#include <cstring>

#include "kernels/detail/cluster_forest.hpp"

namespace orthoflow::kernels {

namespace {

using detail::check;
using detail::Forest;
using detail::included;

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
/// is visited (the partition is the same, far fewer edges are tested). On a mask thinned to every
/// pixel_step-th row and column, "adjacent" and the window are on that grid. @return whether i is
/// clean.
bool link_window(PointsView p, std::size_t w, std::size_t u, std::size_t v,
                 const ClusterParams& prm, std::uint32_t* parent, bool left_clean) {
  const std::size_t r = prm.pixel_radius, st = prm.pixel_step, i = v * w + u;
  const std::size_t u_lo = u >= r ? u - r : 0, u_hi = std::min(w - 1, u + r),
                    v_lo = v >= r ? v - r : 0;
  Linker link{p,      parent, prm.tolerance * prm.tolerance, p.x[i],
              p.y[i], p.z[i], static_cast<std::uint32_t>(i)};
  if (left_clean) {
    link.visit(i - st);
    if (link.root != i) {  // i joined its left neighbour's component
      for (std::size_t vv = v_lo; vv < v && u + r < w; vv += st) { link.visit(vv * w + u + r); }
      parent[i] = link.root;
      return link.clean;
    }
  }
  for (std::size_t vv = v_lo; vv <= v; vv += st) {
    const std::size_t end = vv == v ? u : u_hi + 1;
    for (std::size_t uu = u_lo; uu < end; uu += st) { link.visit(vv * w + uu); }
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
    const bool left_clean =
        previous_clean && previous + params.pixel_step == i && i >= row_start + params.pixel_step;
    previous_clean = link_window(p, w, i - row_start, v, params, scratch.parent.data(), left_clean);
    previous = i;
  }
  return assign_labels_listed(members, params, scratch, labels.first(p.size()));
}

}  // namespace orthoflow::kernels
