#include "ui/png_encode.hpp"

#include <png.h>

#include <cstring>
#include <new>
#include <vector>

namespace orthoflow::ui {

namespace {

struct Sink {
  std::string* out = nullptr;
  bool failed = false;
};

// libpng's write callback: never throws through libpng (a failed append is remembered instead).
void append(png_structp png, png_bytep data, png_size_t length) {
  auto* sink = static_cast<Sink*>(png_get_io_ptr(png));
  if (sink->failed) return;
  try {
    sink->out->append(reinterpret_cast<const char*>(data), length);
  } catch (const std::bad_alloc&) { sink->failed = true; }
}

void flush_nothing(png_structp /*png*/) {}

// The libpng calls, in a frame of their own with no C++ object whose destructor a longjmp from
// libpng's error handler could skip. @return false when libpng reported an error.
bool write_png(png_structp png, png_infop info, const unsigned char* pixels, int stride,
               std::uint32_t width, std::uint32_t height, unsigned char* row, Sink* sink) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, sink, append, flush_nothing);
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_write_info(png, info);
  for (std::uint32_t j = 0; j < height; ++j) {
    const unsigned char* line = pixels + static_cast<std::ptrdiff_t>(j) * stride;
    for (std::uint32_t i = 0; i < width; ++i) {
      std::uint32_t word;
      std::memcpy(&word, line + 4 * static_cast<std::size_t>(i), sizeof word);
      row[3 * i] = static_cast<unsigned char>(word >> 16U);
      row[3 * i + 1] = static_cast<unsigned char>(word >> 8U);
      row[3 * i + 2] = static_cast<unsigned char>(word);
    }
    png_write_row(png, row);
  }
  png_write_end(png, nullptr);
  return true;
}

}  // namespace

std::string encode_rgb24_png(const unsigned char* pixels, int stride, std::uint32_t width,
                             std::uint32_t height) {
  if (width == 0 || height == 0 || pixels == nullptr || stride < 4 * static_cast<int>(width))
    return {};
  std::string out;
  std::vector<unsigned char> row;
  try {
    out.reserve(static_cast<std::size_t>(width) * height);  // most images fit: one allocation
    row.resize(3 * static_cast<std::size_t>(width));
  } catch (const std::bad_alloc&) { return {}; }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (png == nullptr) return {};
  png_infop info = png_create_info_struct(png);
  Sink sink{&out, false};
  const bool written =
      info != nullptr && write_png(png, info, pixels, stride, width, height, row.data(), &sink);
  png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);
  return written && !sink.failed ? out : std::string{};
}

}  // namespace orthoflow::ui
