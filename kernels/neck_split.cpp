// ObjectStage's neck split (kernels/tabletop_stages.hpp, crowded mode, after the occlusion join).
// Two round objects of one height that touch (two cans side by side) meet at their tops, where the
// surface has no concave crease to cut, so their pixels cluster as one piece. Seen from above, on
// the table plane, that piece's footprint is two discs joined by a narrow neck; one object's
// footprint (a can, a mug with its handle, a bowl with its inside, a box) has a single core. Each
// piece's footprint is drawn on a grid and cut at its necks (kernels/detail/neck_scratch.hpp); the
// pixels of each core's share become a piece of their own. Pieces the occlusion join made are left
// whole: an occluder hides the middle of their footprint, which would read as a neck.
#include <algorithm>
#include <cmath>

#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels {

namespace {
constexpr std::size_t PAD = 2;  // empty cells around a footprint (the closing's and the fill's)
}  // namespace

std::size_t ObjectStage::split_necks(PointsView target, std::span<const std::uint32_t> members,
                                     const PlaneBasis& b, std::size_t clusters,
                                     std::uint32_t min_size, const CreaseParams& p) noexcept {
  const std::size_t n = std::min(clusters, joined_.size());
  if (!(p.neck_cell > 0.0F) || n == 0 || members.size() > neck_.u.size()) return clusters;
  const auto labels = std::span(labels_).first(target.size());
  // Each prism pixel on the table plane, and the pixels grouped by piece (a counting sort).
  auto& s = neck_;
  std::fill_n(s.start.begin(), n + 2, 0U);
  for (std::size_t k = 0; k < members.size(); ++k) {
    const std::uint32_t i = members[k];
    const double x = target.x[i] - b.origin[0], y = target.y[i] - b.origin[1],
                 z = target.z[i] - b.origin[2];
    s.u[k] = static_cast<float>(x * b.u[0] + y * b.u[1] + z * b.u[2]);
    s.v[k] = static_cast<float>(x * b.v[0] + y * b.v[1] + z * b.v[2]);
    if (labels[i] >= 0 && static_cast<std::size_t>(labels[i]) < n)
      ++s.start[static_cast<std::size_t>(labels[i]) + 2];
  }
  for (std::size_t c = 2; c < n + 2; ++c) s.start[c] += s.start[c - 1];
  for (std::size_t k = 0; k < members.size(); ++k) {
    const std::int32_t l = labels[members[k]];
    if (l >= 0 && static_cast<std::size_t>(l) < n)
      s.by_cluster[s.start[static_cast<std::size_t>(l) + 1]++] = static_cast<std::uint32_t>(k);
  }
  const double cell = p.neck_cell;
  const detail::NeckRule rule{
      static_cast<std::uint32_t>(std::lround(p.neck_core / cell * detail::NECK_UNIT)), p.neck_ratio,
      p.neck_round};
  const auto min_cells = static_cast<std::size_t>(4.0 * p.neck_core / cell);  // two cores' width
  std::size_t next = clusters;
  std::array<std::size_t, 128> part_size{};
  for (std::size_t c = 0; c < n; ++c) {
    const auto piece = std::span(s.by_cluster).subspan(s.start[c], s.start[c + 1] - s.start[c]);
    if (joined_[c] != 0 || piece.size() < 2 * std::size_t{min_size}) continue;
    float u0 = 1e30F, u1 = -1e30F, v0 = 1e30F, v1 = -1e30F;
    for (const std::uint32_t k : piece)
      u0 = std::min(u0, s.u[k]), u1 = std::max(u1, s.u[k]), v0 = std::min(v0, s.v[k]),
      v1 = std::max(v1, s.v[k]);
    const auto w = static_cast<std::size_t>((u1 - u0) / cell) + 1 + 2 * PAD,
               h = static_cast<std::size_t>((v1 - v0) / cell) + 1 + 2 * PAD;
    if (w > detail::NECK_GRID || h > detail::NECK_GRID) continue;
    if (std::max(w, h) < min_cells + 2 * PAD) continue;  // too small to hold two cores
    const auto cell_of = [&](std::uint32_t k) {
      return (static_cast<std::size_t>((s.v[k] - v0) / cell) + PAD) * w +
             static_cast<std::size_t>((s.u[k] - u0) / cell) + PAD;
    };
    std::fill_n(s.cells.begin(), w * h, std::uint8_t{0});
    for (const std::uint32_t k : piece) s.cells[cell_of(k)] = 1;
    const std::size_t parts = detail::neck_parts(w, h, rule, s);
    if (parts < 2 || parts > part_size.size() || next + parts - 1 > stats_.size()) continue;
    std::fill_n(part_size.begin(), parts, 0U);
    for (const std::uint32_t k : piece)
      ++part_size[std::size_t(std::max<int>(0, s.part[cell_of(k)]))];
    if (*std::min_element(part_size.begin(), part_size.begin() + std::ptrdiff_t(parts)) < min_size)
      continue;
    for (const std::uint32_t k : piece) {
      const int part = std::max<int>(0, s.part[cell_of(k)]);
      if (part > 0) labels[members[k]] = static_cast<std::int32_t>(next + std::size_t(part) - 1);
    }
    next += parts - 1;
  }
  return next;
}

}  // namespace orthoflow::kernels
