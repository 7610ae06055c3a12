#pragma once
/// @file
/// @brief Fisher-Yates shuffle with the portable generator: std::shuffle's algorithm is
/// library-specific, so the same seed would not give the same folds and orders on every platform.
#include <utility>
#include <vector>

#include "core/rng.hpp"

namespace orthoflow::evaluation::detail {

template <class T>
void shuffle(std::vector<T>& v, core::Rng& rng) {
  for (std::size_t i = v.size(); i > 1; --i) { std::swap(v[i - 1], v[rng.below(i)]); }
}

}  // namespace orthoflow::evaluation::detail
