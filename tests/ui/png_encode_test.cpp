// The camera view's PNG encoder (ui/png_encode.hpp), read back by an independent decoder (cairo's
// PNG reader, which uses libpng's reading side): every pixel comes back exactly, for widths that
// are and are not multiples of anything, padded strides, and a noisy image like a camera's; bad
// arguments give "".
#include "ui/png_encode.hpp"

#include <cairo.h>
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

namespace orthoflow::ui {
namespace {

struct Reader {
  const std::string* png;
  std::size_t at = 0;
};

cairo_status_t read_png(void* closure, unsigned char* data, unsigned int length) {
  auto* r = static_cast<Reader*>(closure);
  if (r->at + length > r->png->size()) return CAIRO_STATUS_READ_ERROR;
  std::memcpy(data, r->png->data() + r->at, length);
  r->at += length;
  return CAIRO_STATUS_SUCCESS;
}

// The image as 0x00RRGGBB words, or empty when it does not decode.
std::vector<std::uint32_t> decode(const std::string& png, int& width, int& height) {
  Reader reader{&png};
  cairo_surface_t* s = cairo_image_surface_create_from_png_stream(read_png, &reader);
  std::vector<std::uint32_t> pixels;
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    width = cairo_image_surface_get_width(s);
    height = cairo_image_surface_get_height(s);
    const int stride = cairo_image_surface_get_stride(s);
    const unsigned char* data = cairo_image_surface_get_data(s);
    for (int j = 0; j < height; ++j) {
      for (int i = 0; i < width; ++i) {
        std::uint32_t word;
        std::memcpy(&word, data + j * stride + 4 * i, sizeof word);
        pixels.push_back(word & 0x00FFFFFFU);
      }
    }
  }
  cairo_surface_destroy(s);
  return pixels;
}

TEST(PngEncode, EveryPixelComesBackExactly) {
  std::mt19937 random(7);
  for (const auto& [w, h, pad] : {std::tuple{1, 1, 0}, std::tuple{3, 2, 4}, std::tuple{17, 5, 12},
                                  std::tuple{320, 240, 0}, std::tuple{321, 3, 60}}) {
    const int stride = 4 * w + pad;
    std::vector<unsigned char> image(static_cast<std::size_t>(stride) * h, 0xAB);
    std::vector<std::uint32_t> expected;
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) {
        const auto word =
            static_cast<std::uint32_t>(random()) | 0xFF000000U;  // unused byte: ignored
        std::memcpy(image.data() + j * stride + 4 * i, &word, sizeof word);
        expected.push_back(word & 0x00FFFFFFU);
      }
    }
    const std::string png = encode_rgb24_png(image.data(), stride, static_cast<std::uint32_t>(w),
                                             static_cast<std::uint32_t>(h));
    int dw = 0, dh = 0;
    EXPECT_EQ(decode(png, dw, dh), expected) << w << " x " << h << " stride " << stride;
    EXPECT_EQ(dw, w);
    EXPECT_EQ(dh, h);
  }
}

TEST(PngEncode, BadArgumentsGiveNoImage) {
  std::vector<unsigned char> image(64, 0);
  EXPECT_EQ(encode_rgb24_png(nullptr, 16, 4, 1), "");
  EXPECT_EQ(encode_rgb24_png(image.data(), 16, 0, 1), "");
  EXPECT_EQ(encode_rgb24_png(image.data(), 16, 4, 0), "");
  EXPECT_EQ(encode_rgb24_png(image.data(), 12, 4, 1), "");  // stride below 4 * width
}

}  // namespace
}  // namespace orthoflow::ui
