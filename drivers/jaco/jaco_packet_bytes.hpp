#pragma once
/// @file
/// @brief Little-endian byte access inside a JACO packet (JACO.md 3), shared by jaco_protocol.cpp
/// (the framing) and jaco_payloads.cpp (the payload codecs). Internal to drivers/jaco: nothing
/// outside those two files includes it. Header only; pure.
#include <cstddef>
#include <cstdint>

#include "drivers/jaco/jaco_protocol.hpp"

namespace orthoflow::drivers::jaco::detail {

/// @brief Reads / writes a little-endian u16 or u32 at @p p. @pre p addresses 2 (4) bytes.
inline std::uint16_t load_u16(const std::byte* p) noexcept {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(p[0]) |
                                    (std::to_integer<unsigned>(p[1]) << 8U));
}
inline void store_u16(std::byte* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::byte>(v & 0xFFU);
  p[1] = static_cast<std::byte>(v >> 8U);
}
inline std::uint32_t load_u32(const std::byte* p) noexcept {
  std::uint32_t v = 0;
  for (unsigned i = 0; i < 4; ++i) v |= std::to_integer<std::uint32_t>(p[i]) << (8U * i);
  return v;
}
inline void store_u32(std::byte* p, std::uint32_t v) noexcept {
  for (unsigned i = 0; i < 4; ++i) p[i] = static_cast<std::byte>((v >> (8U * i)) & 0xFFU);
}

/// @brief Packet offset of body byte @p byte. @pre byte < BODY_BYTES.
constexpr std::size_t body_offset(std::size_t byte) noexcept { return HEADER_BYTES + byte; }

}  // namespace orthoflow::drivers::jaco::detail
