// The neck split's grid kernel (kernels/detail/neck_scratch.hpp). Two passes of a descending flood
// over the cells ordered by their distance to the footprint's edge, with union-find:
// 1. where two components meet at distance s, the one with the lower peak p dies; both are cores
//    when p >= min_core and s <= ratio x p (the persistence rule of watershed by dynamics);
// 2. the same flood again, where components grown from different cores never join: a cell that
//    touches two goes to the one with the higher peak, so each core's share ends at its neck.
#include <algorithm>
#include <array>
#include <utility>

#include "kernels/detail/neck_scratch.hpp"

namespace orthoflow::kernels::detail {

namespace {

constexpr std::uint16_t FAR = 0xFFFF;
constexpr std::size_t CELLS = NECK_GRID * NECK_GRID;
constexpr std::size_t MAX_DIST = NECK_GRID * 2 * NECK_UNIT;  // beyond any footprint on the grid

std::int32_t find(std::vector<std::int32_t>& parent, std::int32_t c) noexcept {
  while (parent[static_cast<std::size_t>(c)] != c) {
    auto& up = parent[static_cast<std::size_t>(c)];
    up = parent[static_cast<std::size_t>(up)];
    c = up;
  }
  return c;
}

/// Fills what the footprint encloses (a bowl's or mug's inside below its rim) from the border.
void fill_holes(std::size_t w, std::size_t h, NeckScratch& s) noexcept {
  std::fill_n(s.spare.begin(), w * h, std::uint8_t{0});  // 1: outside
  std::size_t head = 0, tail = 0;
  const auto push = [&](std::size_t c) {
    if (s.cells[c] == 0 && s.spare[c] == 0) s.spare[c] = 1, s.order[tail++] = std::uint32_t(c);
  };
  for (std::size_t x = 0; x < w; ++x) push(x), push((h - 1) * w + x);
  for (std::size_t y = 0; y < h; ++y) push(y * w), push(y * w + w - 1);
  while (head < tail) {
    const std::size_t c = s.order[head++], x = c % w, y = c / w;
    if (x > 0) push(c - 1);
    if (x + 1 < w) push(c + 1);
    if (y > 0) push(c - w);
    if (y + 1 < h) push(c + w);
  }
  for (std::size_t c = 0; c < w * h; ++c) s.cells[c] = s.spare[c] == 0 ? 1 : 0;
}

/// The 3-4 chamfer distance of every footprint cell to the nearest cell outside it.
void chamfer(std::size_t w, std::size_t h, NeckScratch& s) noexcept {
  const auto relax = [&](std::size_t c, std::size_t from, std::uint32_t step) {
    const std::uint32_t d = std::uint32_t{s.dist[from]} + step;
    if (d < s.dist[c]) s.dist[c] = static_cast<std::uint16_t>(d);
  };
  for (std::size_t c = 0; c < w * h; ++c) s.dist[c] = s.cells[c] != 0 ? FAR : 0;
  for (std::size_t y = 1; y + 1 < h; ++y)
    for (std::size_t x = 1; x + 1 < w; ++x) {
      const std::size_t c = y * w + x;
      relax(c, c - 1, 3), relax(c, c - w, 3), relax(c, c - w - 1, 4), relax(c, c - w + 1, 4);
    }
  for (std::size_t y = h - 2; y >= 1; --y)
    for (std::size_t x = w - 2; x >= 1; --x) {
      const std::size_t c = y * w + x;
      relax(c, c + 1, 3), relax(c, c + w, 3), relax(c, c + w + 1, 4), relax(c, c + w - 1, 4);
    }
}

/// The footprint's cells, farthest from the edge first (ties: lower index first). @return count.
std::size_t sort_by_distance(std::size_t w, std::size_t h, NeckScratch& s) noexcept {
  std::fill(s.count.begin(), s.count.end(), 0U);
  std::size_t n = 0;
  for (std::size_t c = 0; c < w * h; ++c)
    if (s.dist[c] > 0) ++s.count[MAX_DIST - std::min<std::size_t>(s.dist[c], MAX_DIST)], ++n;
  std::uint32_t sum = 0;
  for (auto& k : s.count) sum += std::exchange(k, sum);
  for (std::size_t c = 0; c < w * h; ++c)
    if (s.dist[c] > 0)
      s.order[s.count[MAX_DIST - std::min<std::size_t>(s.dist[c], MAX_DIST)]++] =
          static_cast<std::uint32_t>(c);
  return n;
}

/// The processed 8-neighbours' roots of cell @p c, distinct, with the highest distance of the
/// neighbours in each (@p up). @return how many.
std::size_t neighbour_roots(std::size_t c, std::size_t w, NeckScratch& s,
                            std::array<std::int32_t, 8>& roots,
                            std::array<std::uint16_t, 8>& up) noexcept {
  std::size_t n = 0;
  const std::array<std::ptrdiff_t, 8> step{-1,
                                           1,
                                           -std::ptrdiff_t(w),
                                           std::ptrdiff_t(w),
                                           -std::ptrdiff_t(w) - 1,
                                           -std::ptrdiff_t(w) + 1,
                                           std::ptrdiff_t(w) - 1,
                                           std::ptrdiff_t(w) + 1};
  for (const std::ptrdiff_t d : step) {
    const auto y = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(c) + d);
    if (s.parent[y] < 0) continue;
    const std::int32_t r = find(s.parent, s.parent[y]);
    const auto at = std::find(roots.begin(), roots.begin() + std::ptrdiff_t(n), r);
    const auto j = static_cast<std::size_t>(at - roots.begin());
    if (j == n) roots[n] = r, up[n] = 0, ++n;
    up[j] = std::max(up[j], s.dist[y]);
  }
  return n;
}

/// Does root @p a hold the higher peak (ties: the earlier born)?
bool higher(const NeckScratch& s, std::int32_t a, std::int32_t b) noexcept {
  const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
  return s.peak[ua] != s.peak[ub] ? s.peak[ua] > s.peak[ub] : s.birth[ua] < s.birth[ub];
}

}  // namespace

NeckScratch::NeckScratch(std::size_t max_points)
    : cells(CELLS),
      spare(CELLS),
      dist(CELLS),
      order(CELLS),
      count(MAX_DIST + 1),
      parent(CELLS),
      peak(CELLS),
      birth(CELLS),
      marked(CELLS),
      part(CELLS),
      u(max_points),
      v(max_points),
      by_cluster(max_points),
      start(max_points + 2) {}

std::size_t neck_parts(std::size_t w, std::size_t h, const NeckRule& rule,
                       NeckScratch& s) noexcept {
  if (w < 3 || h < 3 || w > NECK_GRID || h > NECK_GRID) return 0;
  fill_holes(w, h, s);
  chamfer(w, h, s);
  const std::size_t n = sort_by_distance(w, h, s);
  const auto born = [&](std::size_t c, std::size_t k) {
    s.parent[c] = static_cast<std::int32_t>(c);
    s.peak[c] = s.dist[c];
    s.birth[c] = static_cast<std::uint32_t>(k);
  };
  std::array<std::int32_t, 8> roots{};
  std::array<std::uint16_t, 8> up{};
  // Pass 1: which components are cores.
  std::fill_n(s.parent.begin(), w * h, -1);
  std::fill_n(s.marked.begin(), w * h, std::uint8_t{0});
  std::size_t cores = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t c = s.order[k];
    const std::size_t m = neighbour_roots(c, w, s, roots, up);
    born(c, k);
    std::int32_t top = static_cast<std::int32_t>(c);
    for (std::size_t j = 0; j < m; ++j) {
      const std::int32_t a = higher(s, roots[j], top) ? roots[j] : top;
      const std::int32_t b = a == roots[j] ? top : roots[j];
      const std::uint32_t low = s.peak[static_cast<std::size_t>(b)];
      if (low >= rule.min_core && float(s.dist[c]) <= rule.ratio * float(low)) {
        for (const std::int32_t r : {a, b}) {
          auto& mark = s.marked[s.order[s.birth[static_cast<std::size_t>(r)]]];
          cores += mark == 0 ? 1 : 0;
          mark = 1;
        }
      }
      s.parent[static_cast<std::size_t>(b)] = a;
      top = a;
    }
  }
  std::fill_n(s.part.begin(), w * h, std::int8_t{-1});
  if (cores < 2) return cores;
  // Pass 2: flood again; components of different cores never join.
  std::fill_n(s.parent.begin(), w * h, -1);
  std::int8_t next = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t c = s.order[k];
    const std::size_t m = neighbour_roots(c, w, s, roots, up);
    born(c, k);
    s.part[c] = s.marked[c] != 0 && next < INT8_MAX ? next++ : std::int8_t{-1};
    // A cell joins the core of its steepest neighbour (the highest distance; ties: the first
    // core), so a core's share spreads down its own slopes and not along the footprint's edge
    // past the neck. Components of no core (lesser peaks) join the cell's.
    std::int32_t chosen = -1;
    std::size_t best = 0;
    for (std::size_t j = 0; j < m; ++j) {
      const std::int8_t part = s.part[static_cast<std::size_t>(roots[j])];
      if (part < 0) continue;
      const std::int8_t chosen_part = chosen >= 0 ? s.part[static_cast<std::size_t>(chosen)] : 0;
      if (chosen < 0 || up[j] > up[best] || (up[j] == up[best] && part < chosen_part))
        chosen = roots[j], best = j;
    }
    if (chosen < 0 && m > 0) chosen = roots[0];
    if (chosen < 0) continue;
    const std::int8_t label = s.part[static_cast<std::size_t>(chosen)];
    s.parent[c] = chosen;
    for (std::size_t j = 0; j < m; ++j)
      if (roots[j] != chosen && (label < 0 || s.part[static_cast<std::size_t>(roots[j])] < 0))
        s.parent[static_cast<std::size_t>(roots[j])] = chosen;
  }
  for (std::size_t c = 0; c < w * h; ++c)
    s.part[c] = s.parent[c] >= 0 ? s.part[static_cast<std::size_t>(find(s.parent, s.parent[c]))]
                                 : std::int8_t{-1};
  // Only round cores are cut: each part's footprint at most max_round times the disc of its
  // core's radius (two cans touching: 1.1-1.4; the pieces of boxes and of half-hidden objects whose
  // outline narrows: 1.7-5 on mOSD).
  std::array<std::uint32_t, 128> area{}, radius{};
  for (std::size_t c = 0; c < w * h; ++c) {
    if (s.part[c] < 0) continue;
    ++area[static_cast<std::size_t>(s.part[c])];
    if (s.marked[c] != 0) radius[static_cast<std::size_t>(s.part[c])] = s.dist[c];
  }
  for (std::size_t k = 0; k < static_cast<std::size_t>(next); ++k) {
    const double r = double(radius[k]) / NECK_UNIT;
    if (double(area[k]) > double(rule.max_round) * 3.141592653589793 * r * r) return 1;
  }
  return static_cast<std::size_t>(next);
}

}  // namespace orthoflow::kernels::detail
