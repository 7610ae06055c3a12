#pragma once
// SIMD body of demosaic_grbg() / demosaic_grbg_packed() (KINECT_V1.md 7.3). Each row takes the
// mosaic rows above and below it (reflected at the first and last rows, so the border rows run
// the same SIMD code), and its columns [2, x_end) go through N = batch<uint8_t>::size pixels at a
// time; columns 0, 1 and [x_end, width) go through demosaic_row_scalar(), which reflects the
// columns -1 and width. A block at x reads mosaic columns [x - 1, x + N] only, and blocks run
// while x + N < width, so no byte outside the image is read.
//
// The arithmetic stays in 8 bits, exactly: with a "halve every byte" built from a 16-bit shift
// (xsimd 8.1 splits 8-bit shifts of AVX2 registers into two SSE halves),
//   avg2(a, b) = (a | b) - ((a ^ b) >> 1)                     == (a + b + 1) / 2
//   avg4(a, b, c, d) = avg2(p, q) - ((a ^ b | c ^ d) & (p ^ q) & 1), p = avg2(a, b), q = avg2(c, d)
//                                                             == (a + b + c + d + 2) / 4
// (checked for all 2^32 inputs when the kernel was written; the tests compare every variant with
// the scalar twin). Each block computes the four candidate means for every lane and picks per
// column parity, so even and odd columns need no deinterleaving.
//
// Stores: the packed form interleaves B, G, R, 0xFF with two levels of zips (per 128-bit lane on
// AVX2 / AVX-512, so 16-byte chunks are reordered through a small buffer); RGB24 interleaves
// R, G, B, 0 the same way and squeezes each 64-bit pair of pixels to 6 bytes, written as
// overlapping 8-byte stores in increasing address order: the last one also writes the first two
// bytes of pixel x + N, which is inside the row and rewritten afterwards (by the next block or the
// scalar tail). NEON has vst3q_u8 / vst4q_u8 and uses them.
#include <cstring>

#include "kernels/detail/bayer_demosaic_kernel.hpp"

namespace orthoflow::kernels::detail {

/// x >> 1 in every byte.
template <class Arch>
inline xsimd::batch<std::uint8_t, Arch> halve_bytes(xsimd::batch<std::uint8_t, Arch> x) noexcept {
  using u8 = xsimd::batch<std::uint8_t, Arch>;
  using u16 = xsimd::batch<std::uint16_t, Arch>;
  return xsimd::bitwise_cast<u8>(xsimd::bitwise_cast<u16>(x) >> 1) & u8(0x7F);
}

/// (a + b + 1) / 2 in every byte.
template <class Arch>
inline xsimd::batch<std::uint8_t, Arch> mean2(xsimd::batch<std::uint8_t, Arch> a,
                                              xsimd::batch<std::uint8_t, Arch> b) noexcept {
  return (a | b) - halve_bytes(a ^ b);
}

/// (a + b + c + d + 2) / 4 in every byte.
template <class Arch>
inline xsimd::batch<std::uint8_t, Arch> mean4(xsimd::batch<std::uint8_t, Arch> a,
                                              xsimd::batch<std::uint8_t, Arch> b,
                                              xsimd::batch<std::uint8_t, Arch> c,
                                              xsimd::batch<std::uint8_t, Arch> d) noexcept {
  using u8 = xsimd::batch<std::uint8_t, Arch>;
  const u8 e = a ^ b;
  const u8 f = c ^ d;
  const u8 p = (a | b) - halve_bytes(e);
  const u8 q = (c | d) - halve_bytes(f);
  return mean2(p, q) - ((e | f) & (p ^ q) & u8(1));
}

/// Writes N = batch<uint8_t>::size pixels from their R, G, B bytes. The RGB24 form may also
/// write the first two bytes of pixel N.
template <class Arch, DemosaicForm FORM>
struct PixelStore {
  using u8 = xsimd::batch<std::uint8_t, Arch>;
  using u16 = xsimd::batch<std::uint16_t, Arch>;
  using u32 = xsimd::batch<std::uint32_t, Arch>;
  using u64 = xsimd::batch<std::uint64_t, Arch>;
  static constexpr std::size_t N = u8::size;
  static constexpr std::size_t CHUNKS = N / 16;  // 128-bit lanes; zips stay inside each

  // Word vector i, 128-bit chunk k holds pixels 16 k + 4 i .. 16 k + 4 i + 3.
  static void interleave(u8 c0, u8 c1, u8 c2, u8 c3, u32 (&w)[4]) noexcept {
    const u16 lo01 = xsimd::bitwise_cast<u16>(xsimd::zip_lo(c0, c1));
    const u16 hi01 = xsimd::bitwise_cast<u16>(xsimd::zip_hi(c0, c1));
    const u16 lo23 = xsimd::bitwise_cast<u16>(xsimd::zip_lo(c2, c3));
    const u16 hi23 = xsimd::bitwise_cast<u16>(xsimd::zip_hi(c2, c3));
    w[0] = xsimd::bitwise_cast<u32>(xsimd::zip_lo(lo01, lo23));
    w[1] = xsimd::bitwise_cast<u32>(xsimd::zip_hi(lo01, lo23));
    w[2] = xsimd::bitwise_cast<u32>(xsimd::zip_lo(hi01, hi23));
    w[3] = xsimd::bitwise_cast<u32>(xsimd::zip_hi(hi01, hi23));
  }

  static void store(DemosaicPixel<FORM>* out, u8 r, u8 g, u8 b) noexcept {
    u32 w[4];
    if constexpr (FORM == DemosaicForm::PACKED) {
      interleave(b, g, r, u8(0xFF), w);  // little-endian 0xFFRRGGBB is bytes B G R FF
      if constexpr (CHUNKS == 1) {
        for (std::size_t i = 0; i < 4; ++i) w[i].store_unaligned(out + 4 * i);
      } else {
        alignas(64) std::uint32_t words[4][N / 4];
        for (std::size_t i = 0; i < 4; ++i) w[i].store_aligned(words[i]);
        for (std::size_t k = 0; k < CHUNKS; ++k) {
          for (std::size_t i = 0; i < 4; ++i)
            std::memcpy(out + 16 * k + 4 * i, words[i] + 4 * k, 16);
        }
      }
    } else {
      interleave(r, g, b, u8(0), w);  // bytes R G B 0
      alignas(64) std::uint64_t pairs[4][N / 8];
      for (std::size_t i = 0; i < 4; ++i) {
        // p0 | p1 << 32  ->  p0 | p1 << 24: two pixels in the low 6 bytes
        const u64 q = xsimd::bitwise_cast<u64>(w[i]);
        ((q & u64(0xFFFFFFU)) | ((q >> 8) & u64(0xFFFFFF000000U))).store_aligned(pairs[i]);
      }
      for (std::size_t k = 0; k < CHUNKS; ++k) {
        for (std::size_t i = 0; i < 4; ++i) {
          for (std::size_t h = 0; h < 2; ++h) {
            std::memcpy(out + 3 * (16 * k + 4 * i + 2 * h), &pairs[i][2 * k + h], 8);
          }
        }
      }
    }
  }
};

#if XSIMD_WITH_NEON64
template <DemosaicForm FORM>
struct PixelStore<xsimd::neon64, FORM> {
  using u8 = xsimd::batch<std::uint8_t, xsimd::neon64>;
  static void store(DemosaicPixel<FORM>* out, u8 r, u8 g, u8 b) noexcept {
    if constexpr (FORM == DemosaicForm::PACKED) {
      const uint8x16x4_t v{{static_cast<uint8x16_t>(b), static_cast<uint8x16_t>(g),
                            static_cast<uint8x16_t>(r), vdupq_n_u8(0xFF)}};
      vst4q_u8(reinterpret_cast<std::uint8_t*>(out), v);
    } else {
      const uint8x16x3_t v{
          {static_cast<uint8x16_t>(r), static_cast<uint8x16_t>(g), static_cast<uint8x16_t>(b)}};
      vst3q_u8(out, v);
    }
  }
};
#endif

/// 0xFF in even lanes: a block starts at an even column, so lane parity is column parity.
struct EvenLanes {
  alignas(64) std::uint8_t mask[64];
};
constexpr EvenLanes make_even_lanes() noexcept {
  EvenLanes t{};
  for (std::size_t i = 0; i < 64; ++i) t.mask[i] = i % 2 == 0 ? 0xFF : 0x00;
  return t;
}
inline constexpr EvenLanes EVEN_LANES = make_even_lanes();

/// Demosaics columns [2, x_end) of one row in blocks of N; returns x_end (2 when no block fits).
template <DemosaicForm FORM, bool ODD_ROW, class Arch>
std::uint32_t demosaic_row_blocks(const std::uint8_t* up, const std::uint8_t* mid,
                                  const std::uint8_t* down, std::uint32_t width,
                                  DemosaicPixel<FORM>* out) noexcept {
  using u8 = xsimd::batch<std::uint8_t, Arch>;
  constexpr std::uint32_t N = u8::size;
  constexpr std::size_t PER_PIXEL = FORM == DemosaicForm::RGB24 ? 3 : 1;
  const auto even = u8::load_aligned(EVEN_LANES.mask) != u8(0);
  std::uint32_t x = 2;
  for (; x + N < width; x += N) {  // reads columns [x - 1, x + N]; pixel x + N exists
    const u8 m = u8::load_unaligned(mid + x);
    const u8 l = u8::load_unaligned(mid + x - 1);
    const u8 r = u8::load_unaligned(mid + x + 1);
    const u8 u = u8::load_unaligned(up + x);
    const u8 d = u8::load_unaligned(down + x);
    const u8 v2 = mean2(u, d);
    const u8 h2 = mean2(l, r);
    const u8 x4 = mean4(u, d, l, r);
    const u8 d4 = mean4(u8::load_unaligned(up + x - 1), u8::load_unaligned(up + x + 1),
                        u8::load_unaligned(down + x - 1), u8::load_unaligned(down + x + 1));
    DemosaicPixel<FORM>* o = out + PER_PIXEL * x;
    if constexpr (ODD_ROW) {  // B G: B pixels at even columns, G at odd
      PixelStore<Arch, FORM>::store(o, xsimd::select(even, d4, v2), xsimd::select(even, x4, m),
                                    xsimd::select(even, m, h2));
    } else {  // G R: G pixels at even columns, R at odd
      PixelStore<Arch, FORM>::store(o, xsimd::select(even, h2, m), xsimd::select(even, m, x4),
                                    xsimd::select(even, v2, d4));
    }
  }
  return x;
}

template <DemosaicForm FORM>
template <class Arch>
void DemosaicKernel<FORM>::operator()(Arch /*arch*/, std::span<const std::uint8_t> bayer,
                                      std::uint32_t width, std::uint32_t height,
                                      std::span<DemosaicPixel<FORM>> out) const noexcept {
  constexpr std::size_t PER_PIXEL = FORM == DemosaicForm::RGB24 ? 3 : 1;
  for (std::uint32_t y = 0; y < height; ++y) {
    const std::uint8_t* up = bayer_row_above(bayer.data(), width, y);
    const std::uint8_t* mid = bayer.data() + std::size_t{width} * y;
    const std::uint8_t* down = bayer_row_below(bayer.data(), width, height, y);
    const bool odd_row = (y & 1U) != 0;
    DemosaicPixel<FORM>* row = out.data() + PER_PIXEL * width * y;
    const std::uint32_t x_end =
        odd_row ? demosaic_row_blocks<FORM, true, Arch>(up, mid, down, width, row)
                : demosaic_row_blocks<FORM, false, Arch>(up, mid, down, width, row);
    // Column 0 reflects column -1; the tail (with column width - 1) comes after the blocks, since
    // the last RGB24 block store spills into pixel x_end.
    demosaic_row_scalar<FORM>(up, mid, down, width, odd_row, 0, 2, row);
    demosaic_row_scalar<FORM>(up, mid, down, width, odd_row, x_end, width, row);
  }
}

}  // namespace orthoflow::kernels::detail

#ifdef OF_SIMD_ARCH
template void orthoflow::kernels::detail::
    DemosaicKernel<orthoflow::kernels::detail::DemosaicForm::RGB24>::operator()<OF_SIMD_ARCH>(
        OF_SIMD_ARCH, std::span<const std::uint8_t>, std::uint32_t, std::uint32_t,
        std::span<std::uint8_t>) const noexcept;
template void orthoflow::kernels::detail::
    DemosaicKernel<orthoflow::kernels::detail::DemosaicForm::PACKED>::operator()<OF_SIMD_ARCH>(
        OF_SIMD_ARCH, std::span<const std::uint8_t>, std::uint32_t, std::uint32_t,
        std::span<std::uint32_t>) const noexcept;
#endif
