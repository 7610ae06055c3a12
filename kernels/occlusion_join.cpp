// ObjectStage's occlusion join (kernels/tabletop_stages.hpp, crowded mode): an object standing
// behind a nearer one (a box behind a bottle) is seen on both sides of it, and the clustering makes
// two pieces of it. Along an image row such an object reads piece A, then the occluder C nearer to
// the camera, then piece B; A and B are joined when enough rows read so and their tops are level
// (one box, one lid). The pieces need not reach the table: the occluder may hide the object's foot
// too. Two different objects of one height side by side behind a third would be joined as well:
// the price of the rule (docs/SEGMENTATION.md).
#include <algorithm>
#include <cmath>

#include "kernels/detail/piece_union.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels {

namespace {

// Pixels allowed between the runs A, C and B of a row: the occluder's shadow (a Kinect v1 sees no
// depth on the far side of a near edge over about 7.5 cm x fx x (1 / z_C - 1 / z_A): up to 35 px
// for an occluder 30 cm in front of an object 80 cm away) and a few unlabelled edge pixels.
constexpr std::uint32_t MAX_GAP_PX = 40;
constexpr std::uint32_t MAX_RUN_GAP_PX = 12;  // holes inside one run
constexpr float MAX_BEHIND_STEP = 0.15F;      // A's and B's depths beside C differ at most this (m)

/// A run of pixels of one label along a row.
struct Run {
  std::int32_t label = -1;
  std::uint32_t first = 0, last = 0;  // columns
  float z_first = 0.0F, z_last = 0.0F;
};

}  // namespace

std::size_t ObjectStage::join_occluded(CloudView cloud, std::span<const std::uint32_t> members,
                                       std::size_t clusters, const CreaseParams& p) noexcept {
  const std::size_t n = std::min(clusters, MAX_OCCLUSION_PIECES);
  if (n < 2 || cloud.width == 0 || clusters > root_.size()) return clusters;
  const std::size_t w = cloud.width;
  const auto labels = std::span(labels_).first(cloud.points.size());
  const auto z = cloud.points.z;
  for (std::size_t c = 0; c < n; ++c) pieces_[c] = {-1e30F, 1e30F, 1e30F, -1e30F};
  std::fill(votes_.begin(), votes_.begin() + static_cast<std::ptrdiff_t>(n * n), 0);
  std::array<Run, 3> runs{};  // the last three runs of the current row: A, C, B
  std::size_t row = SIZE_MAX;
  for (const std::uint32_t i : members) {
    const std::int32_t label = labels[i];
    if (label < 0 || static_cast<std::size_t>(label) >= n) continue;
    const std::size_t r = i / w;
    const auto col = static_cast<std::uint32_t>(i % w);
    auto& piece = pieces_[static_cast<std::size_t>(label)];
    piece = {std::max(piece[0], heights_[i]), std::min(piece[1], heights_[i]),
             std::min(piece[2], static_cast<float>(r)), std::max(piece[3], static_cast<float>(r))};
    if (r != row) {
      row = r;
      runs = {};
    }
    Run& now = runs[2];
    if (now.label == label && col <= now.last + MAX_RUN_GAP_PX) {
      now.last = col;
      now.z_last = z[i];
      continue;
    }
    runs[0] = runs[1];
    runs[1] = runs[2];
    runs[2] = Run{label, col, col, z[i], z[i]};
    const Run &a = runs[0], &c = runs[1], &b = runs[2];
    if (a.label < 0 || a.label == b.label || a.label == c.label || c.label == b.label) continue;
    if (c.first > a.last + MAX_GAP_PX || b.first > c.last + MAX_GAP_PX) continue;
    const bool nearer =
        c.z_first < a.z_last - p.occluder_gap && c.z_last < b.z_first - p.occluder_gap;
    if (!nearer || std::fabs(a.z_last - b.z_first) > MAX_BEHIND_STEP) continue;
    const auto lo = static_cast<std::size_t>(std::min(a.label, b.label)),
               hi = static_cast<std::size_t>(std::max(a.label, b.label));
    auto& v = votes_[lo * n + hi];
    v = static_cast<std::uint16_t>(std::min<std::uint32_t>(v + 1U, UINT16_MAX));
  }
  const auto root = std::span(root_).first(clusters);
  for (std::size_t c = 0; c < clusters; ++c) root[c] = static_cast<std::int32_t>(c);
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = a + 1; b < n; ++b) {
      const std::uint32_t v = votes_[a * n + b];
      if (v < p.occlusion_rows) continue;
      const auto &pa = pieces_[a], &pb = pieces_[b];
      const float rows = std::min(pa[3] - pa[2], pb[3] - pb[2]) + 1.0F;
      if (static_cast<float>(v) < 0.3F * rows) continue;
      if (std::fabs(pa[0] - pb[0]) > p.occlusion_top) continue;
      detail::unite(root, a, b);
    }
  }
  const std::size_t after = detail::relabel(root, new_id_, labels, [&](auto&& f) {
    for (const std::uint32_t i : members) f(std::size_t{i});
  });
  std::fill_n(joined_.begin(), after, std::uint8_t{0});
  for (std::size_t c = 0; c < clusters; ++c)
    if (detail::find_root(root, c) != static_cast<std::int32_t>(c))
      joined_[static_cast<std::size_t>(new_id_[c])] = 1;
  return after;
}

}  // namespace orthoflow::kernels
