#pragma once
// Declaration of the demosaic_grbg() / demosaic_grbg_packed() SIMD functor (body in
// bayer_demosaic.inl, one TU per arch) and the scalar row code shared by the twin and the SIMD
// borders and tails.
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

#include "kernels/bayer_demosaic.hpp"
#include "kernels/simd_arch.hpp"

namespace orthoflow::kernels::detail {

/// The two output forms: RGB24 bytes, or packed 0xFFRRGGBB words.
enum class DemosaicForm { RGB24, PACKED };

template <DemosaicForm FORM>
using DemosaicPixel = std::conditional_t<FORM == DemosaicForm::RGB24, std::uint8_t, std::uint32_t>;

/// Demosaics a whole GRBG image into @p out (3 bytes or 1 word per pixel); instantiated for both
/// forms in every arch unit.
template <DemosaicForm FORM>
struct DemosaicKernel {
  template <class Arch>
  void operator()(Arch arch, std::span<const std::uint8_t> bayer, std::uint32_t width,
                  std::uint32_t height, std::span<DemosaicPixel<FORM>> out) const noexcept;
};

/// The mosaic rows above and below row @p y, reflected at the first and last rows (row -1 is
/// row 1, row height is row height - 2).
inline const std::uint8_t* bayer_row_above(const std::uint8_t* bayer, std::uint32_t width,
                                           std::uint32_t y) noexcept {
  return bayer + std::size_t{width} * (y == 0 ? 1U : y - 1U);
}
inline const std::uint8_t* bayer_row_below(const std::uint8_t* bayer, std::uint32_t width,
                                           std::uint32_t height, std::uint32_t y) noexcept {
  return bayer + std::size_t{width} * (y + 1U == height ? height - 2U : y + 1U);
}

/// Writes pixel x of one output row.
template <DemosaicForm FORM>
inline void put_pixel(DemosaicPixel<FORM>* row, std::uint32_t x, unsigned r, unsigned g,
                      unsigned b) noexcept {
  if constexpr (FORM == DemosaicForm::RGB24) {
    row[3 * std::size_t{x}] = static_cast<std::uint8_t>(r);
    row[3 * std::size_t{x} + 1] = static_cast<std::uint8_t>(g);
    row[3 * std::size_t{x} + 2] = static_cast<std::uint8_t>(b);
  } else {
    row[x] = DEMOSAIC_ALPHA | (r << 16) | (g << 8) | b;
  }
}

/// Demosaics columns [begin, end) of one row: @p mid is the row, @p up and @p down its
/// (already reflected) neighbour rows, @p odd_row whether it is a B G row. Columns -1 and width
/// are reflected to 1 and width - 2. Reads only columns [0, width) of the three rows.
template <DemosaicForm FORM>
inline void demosaic_row_scalar(const std::uint8_t* up, const std::uint8_t* mid,
                                const std::uint8_t* down, std::uint32_t width, bool odd_row,
                                std::uint32_t begin, std::uint32_t end,
                                DemosaicPixel<FORM>* out) noexcept {
  for (std::uint32_t x = begin; x < end; ++x) {
    const std::uint32_t l = x == 0 ? 1U : x - 1U;
    const std::uint32_t r = x + 1U == width ? width - 2U : x + 1U;
    const unsigned m = mid[x];
    const bool odd_col = (x & 1U) != 0;
    if (odd_row == odd_col) {  // G: the two row neighbours and the two column neighbours
      const unsigned h2 = (mid[l] + mid[r] + 1U) / 2U;
      const unsigned v2 = (up[x] + down[x] + 1U) / 2U;
      // even row: R left/right, B above/below; odd row: B left/right, R above/below
      if (odd_row) {
        put_pixel<FORM>(out, x, v2, m, h2);
      } else {
        put_pixel<FORM>(out, x, h2, m, v2);
      }
    } else {  // R or B: G from the 4 edge neighbours, the other colour from the 4 diagonals
      const unsigned x4 = (up[x] + down[x] + mid[l] + mid[r] + 2U) / 4U;
      const unsigned d4 = (up[l] + up[r] + down[l] + down[r] + 2U) / 4U;
      if (odd_row) {
        put_pixel<FORM>(out, x, d4, x4, m);  // B pixel
      } else {
        put_pixel<FORM>(out, x, m, x4, d4);  // R pixel
      }
    }
  }
}

}  // namespace orthoflow::kernels::detail
