#include "formats/png_depth.hpp"

#include <png.h>

#include <bit>
#include <csetjmp>
#include <cstring>
#include <new>
#include <vector>

#include "formats/file_bytes.hpp"

namespace orthoflow::formats {

namespace {

/// The bytes libpng reads from; a read past the end is remembered and ends the decode.
struct Source {
  std::span<const char> bytes;
  std::size_t at = 0;
  bool truncated = false;
};

void read_from(png_structp png, png_bytep data, png_size_t length) {
  auto* src = static_cast<Source*>(png_get_io_ptr(png));
  if (length > src->bytes.size() - src->at) {
    src->truncated = true;
    png_error(png, "truncated");
  }
  std::memcpy(data, src->bytes.data() + src->at, length);
  src->at += length;
}

/// The encoded bytes; a failed append is remembered, never thrown through libpng's C frames.
struct Sink {
  std::string bytes;
  bool failed = false;
};

void append_to(png_structp png, png_bytep data, png_size_t length) {
  auto* sink = static_cast<Sink*>(png_get_io_ptr(png));
  if (sink->failed) return;
  try {
    sink->bytes.append(reinterpret_cast<const char*>(data), length);
  } catch (const std::bad_alloc&) { sink->failed = true; }
}

void flush_nothing(png_structp /*png*/) {}

/// libpng's warnings are not errors here (an unknown ancillary chunk must not fail a frame).
void ignore_warning(png_structp /*png*/, png_const_charp /*message*/) {}

enum class Step { OK, FAILED, WRONG_TYPE, WRONG_SIZE };

/// The libpng calls, in a frame with no C++ object whose destructor a longjmp could skip.
Step decode(png_structp png, png_infop info, std::uint32_t width, std::uint32_t height,
            png_bytepp rows, Source* src) {
  if (setjmp(png_jmpbuf(png))) return Step::FAILED;
  png_set_read_fn(png, src, read_from);
  png_set_user_limits(png, 16384, 16384);
  png_read_info(png, info);
  if (png_get_bit_depth(png, info) != 16 || png_get_color_type(png, info) != PNG_COLOR_TYPE_GRAY)
    return Step::WRONG_TYPE;
  if (png_get_image_width(png, info) != width || png_get_image_height(png, info) != height)
    return Step::WRONG_SIZE;
  if constexpr (std::endian::native == std::endian::little) png_set_swap(png);
  (void)png_set_interlace_handling(png);
  png_read_update_info(png, info);
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return Step::OK;
}

bool encode(png_structp png, png_infop info, std::uint32_t width, std::uint32_t height,
            png_bytepp rows, Sink* out) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, out, append_to, flush_nothing);
  png_set_IHDR(png, info, width, height, 16, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if constexpr (std::endian::native == std::endian::little) png_set_swap(png);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  return true;
}

IoError bad(IoError::Code code, const std::string& name, const std::string& what) {
  return IoError{code, name + ": " + what};
}

}  // namespace

Result<void, IoError> parse_png_depth16(std::span<const char> bytes, const std::string& name,
                                        std::uint32_t width, std::uint32_t height,
                                        std::span<std::uint16_t> out) {
  if (out.size() != std::size_t{width} * height || width == 0 || height == 0)
    return err(bad(IoError::Code::SIZE_MISMATCH, name, "the output does not hold the image"));
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0)
    return err(bad(IoError::Code::BAD_HEADER, name, "not a PNG file (no PNG signature)"));
  std::vector<png_bytep> rows(height);
  for (std::uint32_t j = 0; j < height; ++j)
    rows[j] = reinterpret_cast<png_bytep>(out.data() + std::size_t{j} * width);
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, ignore_warning);
  if (png == nullptr) return err(bad(IoError::Code::OPEN_FAILED, name, "libpng: out of memory"));
  png_infop info = png_create_info_struct(png);
  Source src{bytes};
  const Step step =
      info == nullptr ? Step::FAILED : decode(png, info, width, height, rows.data(), &src);
  png_destroy_read_struct(&png, info != nullptr ? &info : nullptr, nullptr);
  switch (step) {
    case Step::OK:
      return {};
    case Step::WRONG_TYPE:
      return err(bad(IoError::Code::UNSUPPORTED, name,
                     "a depth image must be a 16-bit greyscale PNG (one channel, no alpha)"));
    case Step::WRONG_SIZE:
      return err(bad(IoError::Code::SIZE_MISMATCH, name,
                     "the image is not " + std::to_string(width) + " x " + std::to_string(height)));
    case Step::FAILED:
      break;
  }
  return err(src.truncated ? bad(IoError::Code::TRUNCATED, name, "the PNG stream ends early")
                           : bad(IoError::Code::CORRUPT_DATA, name, "the PNG stream is damaged"));
}

Result<void, IoError> write_png_depth16(const std::filesystem::path& path,
                                        std::span<const std::uint16_t> values, std::uint32_t width,
                                        std::uint32_t height) {
  const std::string name = path.string();
  if (values.size() != std::size_t{width} * height || width == 0 || height == 0)
    return err(bad(IoError::Code::SIZE_MISMATCH, name, "the values are not width x height"));
  std::vector<png_bytep> rows(height);
  for (std::uint32_t j = 0; j < height; ++j)  // libpng does not write through these pointers
    rows[j] = reinterpret_cast<png_bytep>(const_cast<std::uint16_t*>(values.data()) +
                                          std::size_t{j} * width);
  Sink sink;
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, ignore_warning);
  if (png == nullptr) return err(bad(IoError::Code::WRITE_FAILED, name, "libpng: out of memory"));
  png_infop info = png_create_info_struct(png);
  const bool ok = info != nullptr && encode(png, info, width, height, rows.data(), &sink);
  png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);
  if (!ok || sink.failed)
    return err(bad(IoError::Code::WRITE_FAILED, name, "libpng could not encode the image"));
  return write_file_atomically(path, sink.bytes);
}

}  // namespace orthoflow::formats
