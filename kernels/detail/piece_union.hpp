#pragma once
/// @file
/// @brief Union-find over an ObjectStage's pieces (cluster ids), shared by the footprint merge and
/// the occlusion join: joins keep the lowest id as the root, and relabel() renumbers the merged
/// pieces by their lowest member (deterministic) and rewrites the listed pixels' labels.
#include <algorithm>
#include <cstdint>
#include <span>

namespace orthoflow::kernels::detail {

/// @brief The root of piece @p c (path halving).
inline std::int32_t find_root(std::span<std::int32_t> root, std::size_t c) noexcept {
  while (root[c] != static_cast<std::int32_t>(c)) {
    root[c] = root[static_cast<std::size_t>(root[c])];
    c = static_cast<std::size_t>(root[c]);
  }
  return static_cast<std::int32_t>(c);
}

/// @brief Joins the sets of pieces @p a and @p b; the lowest id stays the root.
inline void unite(std::span<std::int32_t> root, std::size_t a, std::size_t b) noexcept {
  const std::int32_t ra = find_root(root, a), rb = find_root(root, b);
  root[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
}

/// @brief Renumbers the sets of @p root (one id per set, by lowest member) into @p new_id and, if
/// any set joined pieces, rewrites @p labels at the pixels @p for_each_member visits (f(i) per
/// pixel index). @return the number of sets.
template <class ForEachMember>
std::size_t relabel(std::span<std::int32_t> root, std::span<std::int32_t> new_id,
                    std::span<std::int32_t> labels, ForEachMember&& for_each_member) noexcept {
  std::size_t merged = 0;
  for (std::size_t c = 0; c < root.size(); ++c) {
    const auto r = static_cast<std::size_t>(find_root(root, c));
    new_id[c] = r == c ? static_cast<std::int32_t>(merged++) : new_id[r];  // a root is its lowest
  }
  if (merged == root.size()) return merged;
  for_each_member([&](std::size_t i) {
    if (labels[i] >= 0) labels[i] = new_id[static_cast<std::size_t>(labels[i])];
  });
  return merged;
}

}  // namespace orthoflow::kernels::detail
