#pragma once
/// @file
/// @brief The one seeded random generator of orthoflow: xoshiro256** (Blackman and Vigna 2018)
/// seeded through SplitMix64, with integer-only range reduction and a transcendental-free normal
/// approximation, so that a sequence is identical on every platform and compiler (x86-64, aarch64).
/// The standard library's distributions are not portable across implementations, so orthoflow never
/// uses them where results must reproduce (RANSAC, synthetic scenes, evaluation folds and orders).
#include <cstdint>

namespace orthoflow::core {

/// @brief xoshiro256** with portable helpers.
/// @note A value type: copy it to fork the stream. Not thread-safe; give each thread (or task) its
/// own. Deterministic: the same seed gives the same sequence everywhere (exact arithmetic only).
class Rng {
 public:
  /// @brief Seeds the 256-bit state from @p seed with SplitMix64 (never all zero).
  explicit Rng(std::uint64_t seed) noexcept {
    for (std::uint64_t& s : state_) { s = splitmix64(seed); }
  }

  /// @brief The next 64 random bits.
  std::uint64_t next() noexcept {
    const std::uint64_t result = rotl(state_[1] * 5, 7) * 9;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }

  /// @brief Uniform integer in [0, n) by Lemire's multiply-shift with rejection (unbiased). @pre n
  /// > 0.
  std::uint64_t below(std::uint64_t n) noexcept {
    // The rejection loop ends with probability >= 1/2 per draw; in practice almost always at once.
    while (true) {
      const unsigned __int128 m = static_cast<unsigned __int128>(next()) * n;
      const auto low = static_cast<std::uint64_t>(m);
      if (low >= (0 - n) % n) { return static_cast<std::uint64_t>(m >> 64); }
    }
  }

  /// @brief Uniform double in [0, 1) with 53 random bits.
  double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  /// @brief Uniform double in [lo, hi).
  double uniform(double lo, double hi) noexcept { return lo + (hi - lo) * uniform(); }

  /// @brief Approximately standard normal: the Irwin-Hall sum of 12 uniforms minus 6 (mean 0,
  /// variance 1, tails cut at +-6). Exact arithmetic only, so identical on every platform.
  double normal() noexcept {
    double sum = 0.0;
    for (int i = 0; i < 12; ++i) { sum += uniform(); }
    return sum - 6.0;
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& x) noexcept {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }

  std::uint64_t state_[4]{};
};

}  // namespace orthoflow::core
