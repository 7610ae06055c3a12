#include "kernels/bayer_demosaic.hpp"

#include "core/assert.hpp"
#include "kernels/detail/bayer_demosaic_kernel.hpp"

namespace orthoflow::kernels {

namespace {

[[maybe_unused]] bool valid_shape(std::uint32_t width, std::uint32_t height) noexcept {
  return width >= 2 && height >= 2 && width % 2 == 0 && height % 2 == 0;
}

template <detail::DemosaicForm FORM>
void demosaic_scalar(std::span<const std::uint8_t> bayer, std::uint32_t width, std::uint32_t height,
                     std::span<detail::DemosaicPixel<FORM>> out) noexcept {
  constexpr std::size_t PER_PIXEL = FORM == detail::DemosaicForm::RGB24 ? 3 : 1;
  for (std::uint32_t y = 0; y < height; ++y) {
    const std::uint8_t* mid = bayer.data() + std::size_t{width} * y;
    detail::demosaic_row_scalar<FORM>(detail::bayer_row_above(bayer.data(), width, y), mid,
                                      detail::bayer_row_below(bayer.data(), width, height, y),
                                      width, (y & 1U) != 0, 0, width,
                                      out.data() + PER_PIXEL * width * y);
  }
}

}  // namespace

void demosaic_grbg_scalar(std::span<const std::uint8_t> bayer, std::uint32_t width,
                          std::uint32_t height, std::span<std::uint8_t> rgb) noexcept {
  OF_ASSERT(valid_shape(width, height), "demosaic_grbg: width and height must be even and >= 2");
  OF_ASSERT(bayer.size() == std::size_t{width} * height && rgb.size() == 3 * bayer.size(),
            "demosaic_grbg: size mismatch");
  demosaic_scalar<detail::DemosaicForm::RGB24>(bayer, width, height, rgb);
}

void demosaic_grbg(std::span<const std::uint8_t> bayer, std::uint32_t width, std::uint32_t height,
                   std::span<std::uint8_t> rgb) noexcept {
  OF_ASSERT(valid_shape(width, height), "demosaic_grbg: width and height must be even and >= 2");
  OF_ASSERT(bayer.size() == std::size_t{width} * height && rgb.size() == 3 * bayer.size(),
            "demosaic_grbg: size mismatch");
  static auto dispatched =
      xsimd::dispatch<SimdArchs>(detail::DemosaicKernel<detail::DemosaicForm::RGB24>{});
  dispatched(bayer, width, height, rgb);
}

void demosaic_grbg_packed_scalar(std::span<const std::uint8_t> bayer, std::uint32_t width,
                                 std::uint32_t height, std::span<std::uint32_t> rgb) noexcept {
  OF_ASSERT(valid_shape(width, height),
            "demosaic_grbg_packed: width and height must be even and >= 2");
  OF_ASSERT(bayer.size() == std::size_t{width} * height && rgb.size() == bayer.size(),
            "demosaic_grbg_packed: size mismatch");
  demosaic_scalar<detail::DemosaicForm::PACKED>(bayer, width, height, rgb);
}

void demosaic_grbg_packed(std::span<const std::uint8_t> bayer, std::uint32_t width,
                          std::uint32_t height, std::span<std::uint32_t> rgb) noexcept {
  OF_ASSERT(valid_shape(width, height),
            "demosaic_grbg_packed: width and height must be even and >= 2");
  OF_ASSERT(bayer.size() == std::size_t{width} * height && rgb.size() == bayer.size(),
            "demosaic_grbg_packed: size mismatch");
  static auto dispatched =
      xsimd::dispatch<SimdArchs>(detail::DemosaicKernel<detail::DemosaicForm::PACKED>{});
  dispatched(bayer, width, height, rgb);
}

void mosaic_grbg(std::span<const std::uint8_t> rgb, std::uint32_t width, std::uint32_t height,
                 std::span<std::uint8_t> bayer) noexcept {
  OF_ASSERT(valid_shape(width, height), "mosaic_grbg: width and height must be even and >= 2");
  OF_ASSERT(bayer.size() == std::size_t{width} * height && rgb.size() == 3 * bayer.size(),
            "mosaic_grbg: size mismatch");
  for (std::uint32_t y = 0; y < height; ++y) {
    for (std::uint32_t x = 0; x < width; ++x) {
      const std::size_t i = std::size_t{width} * y + x;
      // G where y and x have the same parity, R on even rows, B on odd rows (KINECT_V1.md 7.3)
      const std::size_t channel = (y & 1U) == (x & 1U) ? 1 : ((y & 1U) == 0 ? 0 : 2);
      bayer[i] = rgb[3 * i + channel];
    }
  }
}

}  // namespace orthoflow::kernels
