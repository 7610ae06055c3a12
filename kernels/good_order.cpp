#include <algorithm>
#include <cmath>

#include "kernels/detail/good_order.hpp"

namespace orthoflow::kernels::detail {

namespace {

// H = -sum p log2 p over non-empty bins, float terms summed in bin order and negated at the end
// (GOOD_REFERENCE.md section 7; thesis eq. for the projection entropy).
float entropy_of(std::span<const float> p) noexcept {
  float h = 0.0F;
  for (const float v : p) {
    if (v != 0.0F) { h += v * std::log2(v); }
  }
  return -h;
}

// Variance of the 1-based flattened index: mu = sum (i+1) p_i in float, sigma^2 = sum ((i+1) -
// mu)^2 p_i with the square in double accumulated into float, as the reference does (section 8).
float variance_of(std::span<const float> p) noexcept {
  float mu = 0.0F;
  for (std::size_t i = 0; i < p.size(); ++i) { mu += static_cast<float>(i + 1) * p[i]; }
  float var = 0.0F;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double d = static_cast<double>(static_cast<float>(i + 1) - mu);
    var = static_cast<float>(static_cast<double>(var) + d * d * static_cast<double>(p[i]));
  }
  return var;
}

// Highest entropy first (first maximum wins: YoZ < XoZ < XoY); of the other two, in canonical order
// A < B, A comes second when var_A <= var_B (the smaller variance second, ties keep canonical
// order).
std::array<GoodView, 3> order_of(const std::array<float, 3>& h,
                                 const std::array<float, 3>& var) noexcept {
  std::size_t first = 0;
  for (std::size_t v = 1; v < 3; ++v) {
    if (h[v] > h[first]) { first = v; }
  }
  const std::size_t a = first == 0 ? 1 : 0;
  const std::size_t b = first == 2 ? 1 : 2;
  const bool a_second = var[a] <= var[b];
  return {static_cast<GoodView>(first), static_cast<GoodView>(a_second ? a : b),
          static_cast<GoodView>(a_second ? b : a)};
}

}  // namespace

GoodOrderOut good_normalise_and_order(std::span<const std::uint32_t> counts,
                                      const std::array<std::size_t, 3>& kept, std::size_t bins,
                                      std::span<float> out) noexcept {
  const std::size_t nn = bins * bins;
  GoodOrderOut r;
  for (std::size_t v = 0; v < 3; ++v) {
    const std::span<float> block = out.subspan(v * nn, nn);
    // Divided by the points kept in this view (section 6); a view that kept nothing stays all zero.
    const float total = static_cast<float>(kept[v]);
    for (std::size_t i = 0; i < nn; ++i) {
      block[i] = kept[v] == 0 ? 0.0F : static_cast<float>(counts[v * nn + i]) / total;
    }
    r.empty_view = r.empty_view || kept[v] == 0;
    r.entropy[v] = entropy_of(block);
    r.variance[v] = variance_of(block);
  }
  r.order = order_of(r.entropy, r.variance);
  // Permute the canonical blocks into the chosen order with block swaps (no extra memory).
  std::array<std::size_t, 3> where{0, 1, 2};  // where[view] = current block position
  std::array<std::size_t, 3> at{0, 1, 2};     // at[position] = view held there
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t want = static_cast<std::size_t>(r.order[k]);
    const std::size_t pos = where[want];
    if (pos == k) { continue; }
    std::swap_ranges(out.begin() + static_cast<std::ptrdiff_t>(k * nn),
                     out.begin() + static_cast<std::ptrdiff_t>((k + 1) * nn),
                     out.begin() + static_cast<std::ptrdiff_t>(pos * nn));
    where[at[k]] = pos;
    at[pos] = at[k];
    where[want] = k;
    at[k] = want;
  }
  return r;
}

}  // namespace orthoflow::kernels::detail
