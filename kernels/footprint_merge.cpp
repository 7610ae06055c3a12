// ObjectStage's footprint merge (kernels/tabletop_stages.hpp): clusters whose footprints on the
// table overlap are one object seen in pieces (a bowl's near and far walls, a mug's rim and body
// when a depth edge cuts them apart): objects on a table do not overlap from above. Unless one lies
// on the other: with max_rise >= 0 (the crowded mode) two pieces are joined only when the one with
// the smaller footprint rises at most max_rise above the top of the other (a bowl's inside within
// its outside, a mug's rim on its body), so a box the crease split left lying on another stays
// apart.
#include <algorithm>
#include <cmath>

#include "kernels/detail/piece_union.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels {

namespace {

using detail::unite;

/// Calls f(i) for every index of @p members, or for 0..n-1 when @p members is empty.
template <class F>
void for_each_member(std::span<const std::uint32_t> members, std::size_t n, F&& f) noexcept {
  if (members.empty()) {
    for (std::size_t i = 0; i < n; ++i) f(i);
  } else {
    for (const std::uint32_t i : members) f(std::size_t{i});
  }
}

}  // namespace

// Union-find over the overlapping pairs; merged ids renumbered by lowest member (deterministic).
std::size_t ObjectStage::merge_footprints(PointsView target, std::span<const std::uint32_t> members,
                                          const PlaneBasis& b, std::size_t clusters, float overlap,
                                          float max_rise, float stand_height,
                                          float attach_gap) noexcept {
  if (clusters < 2 || clusters > footprints_.size()) return clusters;
  const auto labels = std::span(labels_).first(target.size());
  for (std::size_t c = 0; c < clusters; ++c) {
    footprints_[c] = {1e30, -1e30, 1e30, -1e30, -1e30, 1e30, 0.0};
  }
  for_each_member(members, target.size(), [&](std::size_t i) {
    if (labels[i] < 0) return;
    const double x = target.x[i] - b.origin[0], y = target.y[i] - b.origin[1],
                 z = target.z[i] - b.origin[2];
    const double u = x * b.u[0] + y * b.u[1] + z * b.u[2], v = x * b.v[0] + y * b.v[1] + z * b.v[2];
    auto& f = footprints_[static_cast<std::size_t>(labels[i])];
    const double height = heights_[i];
    f = {std::min(f[0], u),
         std::max(f[1], u),
         std::min(f[2], v),
         std::max(f[3], v),
         std::max(f[4], height),
         std::min(f[5], height),
         0.0};
  });
  const auto root = std::span(root_);
  for (std::size_t c = 0; c < clusters; ++c) root[c] = static_cast<std::int32_t>(c);
  for (std::size_t i = 0; i < clusters; ++i) {
    for (std::size_t j = i + 1; j < clusters; ++j) {
      const auto &a = footprints_[i], &c = footprints_[j];
      const double w = std::min(a[1], c[1]) - std::max(a[0], c[0]),
                   h = std::min(a[3], c[3]) - std::max(a[2], c[2]);
      const double smaller = std::min((a[1] - a[0]) * (a[3] - a[2]), (c[1] - c[0]) * (c[3] - c[2]));
      const double area_a = (a[1] - a[0]) * (a[3] - a[2]), area_c = (c[1] - c[0]) * (c[3] - c[2]);
      const double rise = area_a <= area_c ? a[4] - c[4] : c[4] - a[4];
      const bool within = max_rise < 0.0F || rise <= double{max_rise};
      const bool overlapping = w > 0.0 && h > 0.0 && w * h >= overlap * smaller;
      if (overlapping && !within) footprints_[i][6] = footprints_[j][6] = 1.0;  // one lies on one
      if (overlapping && within) unite(root, i, j);
    }
  }
  // Crowded mode: a piece that neither stands on the table nor lies on another piece (a mug's
  // handle the crease cut off) hangs on the piece whose footprint is nearest, if one is within
  // attach_gap. Pieces of a pair that overlap but rise apart lie one on the other: they stay.
  for (std::size_t i = 0; max_rise >= 0.0F && i < clusters; ++i) {
    const auto& a = footprints_[i];
    if (a[5] <= double{stand_height} || a[6] != 0.0) continue;
    double best = double{attach_gap};
    std::size_t nearest = i;
    for (std::size_t j = 0; j < clusters; ++j) {
      const auto& c = footprints_[j];
      const double du = std::max({0.0, c[0] - a[1], a[0] - c[1]});
      const double dv = std::max({0.0, c[2] - a[3], a[2] - c[3]});
      const double gap = std::sqrt(du * du + dv * dv);
      if (j != i && gap <= best) best = gap, nearest = j;
    }
    if (nearest != i) unite(root, i, nearest);
  }
  return detail::relabel(root.first(clusters), new_id_, labels,
                         [&](auto&& f) { for_each_member(members, target.size(), f); });
}

}  // namespace orthoflow::kernels
