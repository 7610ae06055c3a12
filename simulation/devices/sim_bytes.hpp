#pragma once
/// @file
/// @brief (internal) Little-endian field access for the simulated Kinect's protocol code
/// (sim_kinect_device.cpp, sim_kinect_audio.cpp), written for the simulator: independent of the
/// driver's codec, so the driver is checked against a second implementation.
/// @note Pure; no bounds checks beyond the caller's (@pre at + width <= size).
#include <cstddef>
#include <cstdint>
#include <span>

namespace orthoflow::simulation {

/// @brief Stores @p v at @p at, low byte first. @pre at + 2 <= out.size().
inline void sim_put_le16(std::span<std::uint8_t> out, std::size_t at, std::uint16_t v) noexcept {
  out[at] = static_cast<std::uint8_t>(v & 0xFFU);
  out[at + 1] = static_cast<std::uint8_t>(v >> 8);
}

/// @brief Stores @p v at @p at, low byte first. @pre at + 4 <= out.size().
inline void sim_put_le32(std::span<std::uint8_t> out, std::size_t at, std::uint32_t v) noexcept {
  for (std::size_t i = 0; i < 4; ++i)
    out[at + i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFU);
}

/// @brief Stores @p v at @p at, low byte first. @pre at + 4 <= out.size().
inline void sim_put_le32(std::span<std::byte> out, std::size_t at, std::uint32_t v) noexcept {
  for (std::size_t i = 0; i < 4; ++i)
    out[at + i] = std::byte{static_cast<std::uint8_t>(v >> (8 * i))};
}

/// @brief The 16-bit value at @p at. @pre at + 2 <= in.size().
inline std::uint16_t sim_get_le16(std::span<const std::byte> in, std::size_t at) noexcept {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(in[at]) |
                                    (std::to_integer<unsigned>(in[at + 1]) << 8));
}

/// @brief The 32-bit value at @p at. @pre at + 4 <= in.size().
inline std::uint32_t sim_get_le32(std::span<const std::byte> in, std::size_t at) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= std::to_integer<std::uint32_t>(in[at + i]) << (8 * i);
  return v;
}

/// @brief The 32-bit value at @p at. @pre at + 4 <= in.size().
inline std::uint32_t sim_get_le32(std::span<const std::uint8_t> in, std::size_t at) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= std::uint32_t{in[at + i]} << (8 * i);
  return v;
}

}  // namespace orthoflow::simulation
