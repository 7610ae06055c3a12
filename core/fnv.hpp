#pragma once
/// @file
/// @brief FNV-1a, the one 64-bit hash of orthoflow's identifiers and digests: a dictionary's id,
/// a document's sampler seed, an export file's digest. Byte by byte, least significant byte first,
/// so the same on every architecture. Not for security.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <type_traits>

namespace orthoflow::core {

inline constexpr std::uint64_t FNV_OFFSET = 0xcbf29ce484222325ULL;  ///< FNV-1a's offset basis
inline constexpr std::uint64_t FNV_PRIME = 0x100000001b3ULL;

/// @brief @p h after one byte.
[[nodiscard]] constexpr std::uint64_t fnv1a(std::uint64_t h, std::uint8_t byte) noexcept {
  return (h ^ byte) * FNV_PRIME;
}

/// @brief @p h after every byte of the unsigned integer @p value, least significant first.
template <class T>
requires std::is_unsigned_v<T>
[[nodiscard]] constexpr std::uint64_t fnv1a_value(std::uint64_t h, T value) noexcept {
  for (std::size_t i = 0; i < sizeof(T); ++i)
    h = fnv1a(h, static_cast<std::uint8_t>(value >> (8 * i)));
  return h;
}

/// @brief @p h after every byte of @p text.
[[nodiscard]] constexpr std::uint64_t fnv1a(std::uint64_t h, std::string_view text) noexcept {
  for (const char c : text) h = fnv1a(h, static_cast<std::uint8_t>(c));
  return h;
}

}  // namespace orthoflow::core
