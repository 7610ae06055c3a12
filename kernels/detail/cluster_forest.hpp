#pragma once
/// @file
/// @brief What both Euclidean clusterings share (kernels/euclidean_cluster.cpp, the spatial grid,
/// and kernels/euclidean_cluster_organized.cpp, the image-space window): the union-find over
/// ClusterScratch::parent, the test of which points take part, and the check of the parameters
/// and the scratch. Internal to kernels; never allocates.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/euclidean_cluster.hpp"

namespace orthoflow::kernels::detail {

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

/// True if point @p i takes part: no mask or mask[i] set, and all three coordinates finite.
inline bool included(PointsView p, std::span<const std::uint8_t> mask, std::size_t i) {
  return (mask.empty() || mask[i] != 0) && std::isfinite(p.x[i]) && std::isfinite(p.y[i]) &&
         std::isfinite(p.z[i]);
}

/// @p n, or why the clustering cannot run: bad parameters, or a scratch too small for @p n points.
inline Result<std::size_t, ClusterError> check(std::size_t n, const ClusterParams& prm,
                                               const ClusterScratch& s) {
  using Code = ClusterError::Code;
  if (!std::isfinite(prm.tolerance) || !(prm.tolerance > 0.0F)) {
    return err(ClusterError{Code::BAD_PARAMS, prm.tolerance});
  }
  if (prm.min_size > prm.max_size) {
    return err(ClusterError{Code::BAD_PARAMS, double(prm.min_size)});
  }
  if (prm.pixel_radius == 0 || prm.pixel_step == 0 || prm.pixel_radius % prm.pixel_step != 0) {
    return err(ClusterError{Code::BAD_PARAMS, 0.0});
  }
  if (n > s.capacity()) { return err(ClusterError{Code::SCRATCH_TOO_SMALL, double(n)}); }
  return n;
}

}  // namespace orthoflow::kernels::detail
