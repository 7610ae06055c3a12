#pragma once
// GOOD after binning: per-view normalisation, entropy, variance and block ordering
// (GOOD_REFERENCE.md sections 6-8), shared by compute_good() and compute_good_scalar().
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/good.hpp"

namespace orthoflow::kernels::detail {

struct GoodOrderOut {
  std::array<GoodView, 3> order{};
  std::array<float, 3> entropy{};
  std::array<float, 3> variance{};
  bool empty_view = false;
};

/// Writes the ordered descriptor (3 n^2 values) from counts (canonical order) and kept counts.
/// @pre out.size() >= 3 n^2, counts.size() >= 3 n^2
GoodOrderOut good_normalise_and_order(std::span<const std::uint32_t> counts,
                                      const std::array<std::size_t, 3>& kept, std::size_t bins,
                                      std::span<float> out) noexcept;

}  // namespace orthoflow::kernels::detail
