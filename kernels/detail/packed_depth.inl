#pragma once
// SIMD body of unpack_11bit() / unpack_10bit() (KINECT_V1.md 7.1, 7.2). Eight pixels of W bits are
// exactly W bytes, so each 128-bit lane takes one 8-pixel group: it holds the 16 bytes starting at
// the group, an in-lane byte shuffle puts the big-endian byte pair holding the top of pixel j into
// 16-bit lane j (for W = 11 a second shuffle fetches the third byte of the two pixels of a group
// that straddle three bytes), a multiply by 2^shift_j moves each pixel's first bit to bit 15, and
// a shift right by 16 - W leaves the pixel. Multiplies rather than variable shifts: 16-bit
// variable shifts need AVX-512BW, 16-bit multiplies exist everywhere.
//
// The byte shuffle and the lane-wise load are the only per-arch pieces (LaneOps): pshufb on AVX2
// and AVX-512BW, tbl on NEON. SSE2 has no byte shuffle (pshufb is SSSE3); emulating one through
// memory or 16-bit selects takes about as many operations as the scalar loop itself, so that tier
// runs the scalar loop.
//
// A block of G groups loads bytes [b, b + (G - 1) * W + 16); blocks run only while that stays
// within packed_bytes(out.size(), W), and the rest goes to unpack_range_scalar(), which reads only
// the bytes holding its pixels: no byte past the end of the stream is ever read.
#include "kernels/detail/packed_depth_kernel.hpp"

namespace orthoflow::kernels::detail {

/// Per-arch primitives. load(p, stride): 128-bit lane g gets the 16 bytes at p + g * stride.
/// shuffle(x, index): byte i of each 128-bit lane becomes byte index[i] of that lane, or 0 when
/// index[i] >= 0x80. Only the architectures in SimdArchs are specialized.
template <class Arch>
struct LaneOps;

template <>
struct LaneOps<xsimd::sse2> {
  static constexpr bool HAS_SHUFFLE = false;
};

#if XSIMD_WITH_AVX2
template <>
struct LaneOps<xsimd::fma3<xsimd::avx2>> {
  static constexpr bool HAS_SHUFFLE = true;
  using u8 = xsimd::batch<std::uint8_t, xsimd::fma3<xsimd::avx2>>;
  static u8 load(const std::uint8_t* p, std::size_t stride) noexcept {
    const __m128i lane0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
    const __m128i lane1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + stride));
    return _mm256_inserti128_si256(_mm256_castsi128_si256(lane0), lane1, 1);
  }
  static u8 shuffle(u8 x, u8 index) noexcept { return _mm256_shuffle_epi8(x, index); }
};
#endif

#if XSIMD_WITH_AVX512BW
template <>
struct LaneOps<xsimd::avx512bw> {
  static constexpr bool HAS_SHUFFLE = true;
  using u8 = xsimd::batch<std::uint8_t, xsimd::avx512bw>;
  static u8 load(const std::uint8_t* p, std::size_t stride) noexcept {
    auto lane = [p, stride](std::size_t g) {
      return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + g * stride));
    };
    __m512i v = _mm512_castsi128_si512(lane(0));
    v = _mm512_inserti32x4(v, lane(1), 1);
    v = _mm512_inserti32x4(v, lane(2), 2);
    return _mm512_inserti32x4(v, lane(3), 3);
  }
  static u8 shuffle(u8 x, u8 index) noexcept { return _mm512_shuffle_epi8(x, index); }
};
#endif

#if XSIMD_WITH_NEON64
template <>
struct LaneOps<xsimd::neon64> {
  static constexpr bool HAS_SHUFFLE = true;
  using u8 = xsimd::batch<std::uint8_t, xsimd::neon64>;
  static u8 load(const std::uint8_t* p, std::size_t /*stride*/) noexcept {
    return u8::load_unaligned(p);
  }
  static u8 shuffle(u8 x, u8 index) noexcept { return vqtbl1q_u8(x, index); }
};
#endif

/// Shuffle indices and multipliers for one W, repeated for up to four 128-bit lanes.
struct LanePatterns {
  alignas(64) std::uint8_t top[64];     // lane j: low byte = first byte + 1, high = first byte
  alignas(64) std::uint8_t third[64];   // lane j: low byte = first byte + 2 if needed, else zero
  alignas(64) std::uint16_t scale[32];  // lane j: 2^shift_j
};

template <unsigned BITS>
constexpr LanePatterns make_lane_patterns() noexcept {
  LanePatterns t{};
  for (std::size_t b = 0; b < 64; ++b) {
    const std::size_t bit = ((b % 16) / 2) * BITS;  // first bit of pixel j = (b % 16) / 2
    const std::size_t first = bit / 8;
    const bool straddles = bit % 8 + BITS > 16;
    const bool low_byte = b % 2 == 0;  // little-endian lanes: even bytes are the low bytes
    t.top[b] = static_cast<std::uint8_t>(low_byte ? first + 1 : first);
    t.third[b] = static_cast<std::uint8_t>(low_byte && straddles ? first + 2 : 0x80);
  }
  for (std::size_t j = 0; j < 32; ++j) {
    t.scale[j] = static_cast<std::uint16_t>(1U << ((j % 8) * BITS % 8));
  }
  return t;
}

template <unsigned BITS>
inline constexpr LanePatterns LANE_PATTERNS = make_lane_patterns<BITS>();

/// Unpacks whole blocks of 8 * G pixels; returns how many pixels it wrote.
template <unsigned BITS, class Arch>
std::size_t unpack_blocks(const std::uint8_t* packed, std::span<std::uint16_t> out) noexcept {
  using ops = LaneOps<Arch>;
  using u8 = xsimd::batch<std::uint8_t, Arch>;
  using u16 = xsimd::batch<std::uint16_t, Arch>;
  constexpr std::size_t GROUPS = u8::size / 16;           // one 8-pixel group per 128-bit lane
  constexpr std::size_t READ = (GROUPS - 1) * BITS + 16;  // bytes one block loads
  const std::size_t limit = packed_bytes(out.size(), BITS);
  const u8 top_index = u8::load_aligned(LANE_PATTERNS<BITS>.top);
  const u8 third_index = u8::load_aligned(LANE_PATTERNS<BITS>.third);
  const u16 scale = u16::load_aligned(LANE_PATTERNS<BITS>.scale);
  std::size_t k = 0;
  for (std::size_t byte = 0; byte + READ <= limit; byte += GROUPS * BITS, k += u16::size) {
    const u8 raw = ops::load(packed + byte, BITS);
    // (top << shift) mod 2^16 are bits 23..8 of the 24-bit window shifted left by `shift`.
    u16 v = xsimd::bitwise_cast<u16>(ops::shuffle(raw, top_index)) * scale;
    if constexpr (BITS == 11) {
      v = v | ((xsimd::bitwise_cast<u16>(ops::shuffle(raw, third_index)) * scale) >> 8);
    }
    (v >> static_cast<std::int32_t>(16 - BITS)).store_unaligned(out.data() + k);
  }
  return k;
}

template <unsigned BITS>
template <class Arch>
void UnpackKernel<BITS>::operator()(Arch /*arch*/, std::span<const std::uint8_t> packed,
                                    std::span<std::uint16_t> out) const noexcept {
  std::size_t k = 0;
  if constexpr (LaneOps<Arch>::HAS_SHUFFLE) { k = unpack_blocks<BITS, Arch>(packed.data(), out); }
  unpack_range_scalar<BITS>(packed.data(), k, out.size(), out.data());
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template void orthoflow::kernels::detail::UnpackKernel<11>::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, std::span<const std::uint8_t>, std::span<std::uint16_t>) const noexcept;
template void orthoflow::kernels::detail::UnpackKernel<10>::operator()<OF_SIMD_ARCH>(
    OF_SIMD_ARCH, std::span<const std::uint8_t>, std::span<std::uint16_t>) const noexcept;
#endif
