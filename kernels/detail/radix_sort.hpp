#pragma once
// LSD radix sort of 64-bit keys carrying a 32-bit payload (voxel grid and cluster grid share it).
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

namespace orthoflow::kernels::detail {

/// Sorts keys[0, n) ascending, stable, permuting vals alike; 11-bit digits, only the passes that
/// max_key needs. Uses keys_tmp/vals_tmp as ping-pong buffers; returns true when the result is in them.
inline bool radix_sort_pairs(std::uint64_t* keys, std::uint64_t* keys_tmp, std::uint32_t* vals, std::uint32_t* vals_tmp,
                             std::size_t n, std::uint64_t max_key) noexcept {
  bool swapped = false;
  for (unsigned shift = 0; shift < 64 && (max_key >> shift) != 0; shift += 11) {
    std::array<std::size_t, 2048> count{};
    for (std::size_t i = 0; i < n; ++i) { ++count[(keys[i] >> shift) & 0x7FFU]; }
    std::size_t sum = 0;
    for (auto& c : count) { sum += std::exchange(c, sum); }
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t dst = count[(keys[i] >> shift) & 0x7FFU]++;
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
