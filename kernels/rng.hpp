#pragma once
/// @file
/// @brief Seeded portable random numbers: xoshiro256** seeded through splitmix64, integer-only
/// range reduction, so the sequence is identical on every platform and compiler (x86, ARM).
#include <cstdint>

namespace orthoflow::kernels {

/// @brief xoshiro256** (Blackman and Vigna 2018) with splitmix64 seeding.
/// @note A value type: copy it to fork the stream. Not thread-safe; give each thread its own.
/// Deterministic: the same seed gives the same sequence everywhere (integer arithmetic only).
class Rng {
 public:
  /// @brief Seeds the 256-bit state from @p seed with splitmix64 (never all-zero).
  explicit Rng(std::uint64_t seed) noexcept {
    for (auto& word : s_) { word = splitmix64(seed); }
  }

  /// @brief The next 64 random bits.
  std::uint64_t next() noexcept {
    const std::uint64_t result = rotl(s_[1] * 5U, 7) * 9U;
    const std::uint64_t t = s_[1] << 17U;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  /// @brief Uniform integer in [0, n) by Lemire's multiply-shift with rejection (unbiased).
  /// @pre n > 0 and n <= 2^32.
  std::uint32_t below(std::uint64_t n) noexcept {
    const std::uint64_t bound = n;
    while (true) {
      const std::uint64_t r = next() >> 32U;  // 32 uniform bits
      const std::uint64_t product = r * bound;
      const std::uint64_t low = product & 0xFFFFFFFFULL;
      // Reject the (2^32 mod n) low values that would bias the result.
      if (low >= ((0x100000000ULL - bound) % bound)) { return static_cast<std::uint32_t>(product >> 32U); }
    }
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, unsigned k) noexcept { return (x << k) | (x >> (64U - k)); }
  static std::uint64_t splitmix64(std::uint64_t& state) noexcept {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31U);
  }
  std::uint64_t s_[4]{};
};

}  // namespace orthoflow::kernels
