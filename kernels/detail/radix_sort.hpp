#pragma once
// LSD radix sort of 64-bit keys carrying a 32-bit payload (voxel grid and cluster grid share it).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

namespace orthoflow::kernels::detail {

/// Sorts keys[0, n) ascending, stable, permuting vals alike. Digits of at most 13 bits, as few
/// passes as max_key needs (a 2 m ROI at 5 mm has 26-bit keys: 2 passes). Uses keys_tmp/vals_tmp as
/// ping-pong buffers; returns true when the result is in them. @pre n < 2^32.
inline bool radix_sort_pairs(std::uint64_t* keys, std::uint64_t* keys_tmp, std::uint32_t* vals,
                             std::uint32_t* vals_tmp, std::size_t n,
                             std::uint64_t max_key) noexcept {
  unsigned bits = 0;
  while (bits < 64 && (max_key >> bits) != 0) { ++bits; }
  const unsigned passes = (bits + 12) / 13;
  if (passes == 0) { return false; }
  const unsigned digit = (bits + passes - 1) / passes;
  const std::uint64_t digit_mask = (std::uint64_t{1} << digit) - 1;
  bool swapped = false;
  std::array<std::uint32_t, 8192> count;  // 13-bit digits at most; 32 KiB, stays in L1/L2
  for (unsigned pass = 0; pass < passes; ++pass) {
    const unsigned shift = pass * digit;
    std::fill(count.begin(), count.begin() + static_cast<std::ptrdiff_t>(digit_mask + 1), 0U);
    for (std::size_t i = 0; i < n; ++i) { ++count[(keys[i] >> shift) & digit_mask]; }
    std::uint32_t sum = 0;
    for (std::size_t d = 0; d <= digit_mask; ++d) { sum += std::exchange(count[d], sum); }
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t dst = count[(keys[i] >> shift) & digit_mask]++;
      keys_tmp[dst] = keys[i];
      vals_tmp[dst] = vals[i];
    }
    std::swap(keys, keys_tmp);
    std::swap(vals, vals_tmp);
    swapped = !swapped;
  }
  return swapped;
}

}  // namespace orthoflow::kernels::detail
