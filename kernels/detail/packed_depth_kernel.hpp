#pragma once
// Declaration of the unpack_11bit() / unpack_10bit() SIMD functor; body in packed_depth.inl (one TU
// per arch).
#include <cstddef>
#include <cstdint>
#include <span>

#include "kernels/packed_depth.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

/// Unpacks out.size() pixels of BITS (10 or 11) bits; instantiated for both widths in every arch
/// unit.
template <unsigned BITS>
struct UnpackKernel {
  static_assert(BITS == 10 || BITS == 11, "the Kinect streams are 10 or 11 bits wide");
  template <class Arch>
  void operator()(Arch arch, std::span<const std::uint8_t> packed,
                  std::span<std::uint16_t> out) const noexcept;
};

/// Unpacks pixels [begin, end) of the stream one at a time (shared by the twin and the SIMD tail).
/// Pixel k starts `shift` bits into byte k*BITS/8 and reaches into a third byte only when
/// shift + BITS > 16, so no byte past the one holding the last bit of pixel end-1 is read.
template <unsigned BITS>
inline void unpack_range_scalar(const std::uint8_t* packed, std::size_t begin, std::size_t end,
                                std::uint16_t* out) noexcept {
  constexpr std::uint32_t MASK = (1U << BITS) - 1U;
  for (std::size_t k = begin; k < end; ++k) {
    const std::size_t bit = k * BITS;
    const std::uint8_t* p = packed + bit / 8;
    const unsigned shift = static_cast<unsigned>(bit % 8);
    // A 24-bit big-endian window starting at the pixel's first byte.
    std::uint32_t window = (std::uint32_t{p[0]} << 16) | (std::uint32_t{p[1]} << 8);
    if (shift + BITS > 16) { window |= p[2]; }
    out[k] = static_cast<std::uint16_t>((window >> (24U - BITS - shift)) & MASK);
  }
}

}  // namespace orthoflow::kernels::detail
