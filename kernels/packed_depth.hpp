#pragma once
/// @file
/// @brief Kinect v1 packed depth and IR bit streams to host-order 16-bit pixels (specs/KINECT_V1.md
/// section 7).
///
/// A frame is one continuous MSB-first bit stream: pixel k occupies bits W*k .. W*k+W-1, most
/// significant bit first; W = 11 for 11-bit depth (8 pixels in 11 bytes), W = 10 for 10-bit depth
/// and IR (4 pixels in 5 bytes). Unpacked pixels are host-order uint16 with the upper bits zero;
/// 2047 ("no reading" in 11-bit depth) is just a value here.
#include <cstddef>
#include <cstdint>
#include <span>

namespace orthoflow::kernels {

/// @brief Bytes needed to hold @p pixels pixels of @p bits bits: ceil(pixels * bits / 8).
/// @pre pixels * bits does not overflow std::size_t. @note constexpr, thread-safe.
[[nodiscard]] constexpr std::size_t packed_bytes(std::size_t pixels, unsigned bits) noexcept {
  return (pixels * bits + 7U) / 8U;
}

/// @brief Unpacks out.size() pixels of 11 bits from the MSB-first stream @p packed into @p out.
/// @pre packed.size() >= packed_bytes(out.size(), 11) (OF_ASSERT). An empty @p out is fine.
/// @note Stateless and thread-safe. Reads no byte of @p packed at or past
/// packed_bytes(out.size(), 11). The SIMD variant equals unpack_11bit_scalar() bit for bit; on
/// the SSE2 tier (no byte shuffle before SSSE3) it runs the scalar loop.
void unpack_11bit(std::span<const std::uint8_t> packed, std::span<std::uint16_t> out) noexcept;
/// @brief Scalar reference twin of unpack_11bit(). @pre as unpack_11bit().
void unpack_11bit_scalar(std::span<const std::uint8_t> packed,
                         std::span<std::uint16_t> out) noexcept;

/// @brief Unpacks out.size() pixels of 10 bits (10-bit depth, IR) from the MSB-first stream
/// @p packed into @p out.
/// @pre packed.size() >= packed_bytes(out.size(), 10) (OF_ASSERT). An empty @p out is fine.
/// @note As unpack_11bit(): thread-safe, never reads past packed_bytes(out.size(), 10), equal to
/// unpack_10bit_scalar() bit for bit.
void unpack_10bit(std::span<const std::uint8_t> packed, std::span<std::uint16_t> out) noexcept;
/// @brief Scalar reference twin of unpack_10bit(). @pre as unpack_10bit().
void unpack_10bit_scalar(std::span<const std::uint8_t> packed,
                         std::span<std::uint16_t> out) noexcept;

/// @brief The inverse, for simulators and tests: packs in.size() values, each masked to @p bits
/// bits, MSB first into @p out. The trailing bits of the last byte are zero; bytes of @p out at
/// or past packed_bytes(in.size(), bits) are not touched.
/// @pre out.size() >= packed_bytes(in.size(), bits); bits is 10 or 11 (OF_ASSERT).
/// @note Stateless and thread-safe.
void pack_bits(std::span<const std::uint16_t> in, unsigned bits,
               std::span<std::uint8_t> out) noexcept;

}  // namespace orthoflow::kernels
