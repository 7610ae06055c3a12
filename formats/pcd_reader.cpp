// PCD data sections: binary (packed records), binary_compressed (LZF block, field-major) and ascii.
#include <cstring>
#include <limits>
#include <vector>

#include <lzf.h>

#include "formats/file_bytes.hpp"
#include "formats/pcd_io.hpp"
#include "formats/text_scan.hpp"

namespace orthoflow::formats {
namespace {

/// An LZF back-reference of at most 3 bytes expands to at most 264 bytes, so no valid block grows
/// by more than this factor; a larger declared size is corrupt and never allocated.
constexpr std::uint64_t LZF_MAX_EXPANSION = 88;

IoError at_byte(IoError::Code code, std::string_view name, std::size_t byte,
                const std::string& what) {
  return IoError{code, std::string(name) + ": byte " + std::to_string(byte) + ": " + what};
}

void shape(const PcdHeader& h, kernels::PointCloud& cloud) {
  cloud.resize(h.width, h.height);
  add_fields_for(h.fields, cloud);
}

Result<void, IoError> read_binary(std::span<const char> bytes, const PcdHeader& h,
                                  std::string_view name, kernels::PointCloud& cloud) {
  const std::uint64_t need = h.points * h.point_size();
  const std::size_t have = bytes.size() - h.data_offset;
  if (need > have) {
    return err(at_byte(IoError::Code::TRUNCATED, name, bytes.size(),
                       "binary data holds " + std::to_string(have) + " bytes, header declares " +
                           std::to_string(h.points) + " points x " +
                           std::to_string(h.point_size()) + " bytes"));
  }
  shape(h, cloud);
  decode_records(bytes.subspan(h.data_offset, need), h.fields, h.point_size(), cloud);
  return {};
}

Result<void, IoError> read_compressed(std::span<const char> bytes, const PcdHeader& h,
                                      std::string_view name, kernels::PointCloud& cloud) {
  const std::size_t at = h.data_offset;
  if (bytes.size() - at < 8) {
    return err(at_byte(IoError::Code::TRUNCATED, name, bytes.size(),
                       "no compressed block sizes after DATA"));
  }
  std::uint32_t packed = 0;
  std::uint32_t unpacked = 0;
  std::memcpy(&packed, bytes.data() + at, 4);
  std::memcpy(&unpacked, bytes.data() + at + 4, 4);
  const std::uint64_t need = h.points * h.point_size();
  if (unpacked != need) {
    return err(at_byte(IoError::Code::SIZE_MISMATCH, name, at + 4,
                       "uncompressed size " + std::to_string(unpacked) +
                           " != " + std::to_string(h.points) + " points x " +
                           std::to_string(h.point_size()) + " bytes"));
  }
  if (packed > bytes.size() - at - 8) {
    return err(at_byte(IoError::Code::TRUNCATED, name, bytes.size(),
                       "compressed block of " + std::to_string(packed) + " bytes is cut short"));
  }
  if (need > static_cast<std::uint64_t>(packed) * LZF_MAX_EXPANSION) {
    return err(at_byte(IoError::Code::CORRUPT_DATA, name, at,
                       "compressed block of " + std::to_string(packed) +
                           " bytes cannot expand to " + std::to_string(need)));
  }
  std::vector<char> soa(need);
  if (need > 0) {
    const unsigned got =
        lzf_decompress(bytes.data() + at + 8, packed, soa.data(), static_cast<unsigned>(need));
    if (got != need) {
      return err(at_byte(IoError::Code::CORRUPT_DATA, name, at + 8,
                         "LZF block does not decompress to the declared size"));
    }
  }
  shape(h, cloud);
  if (need == 0) { return {}; }
  for (const PointField& f :
       h.fields) {  // field-major: all points' values of one field, then the next
    decode_field(soa.data() + h.points * f.offset, f.bytes(), f, cloud);
  }
  return {};
}

/// Parses one ASCII token as the field's type and stores it in the record at @p dst.
bool store_token(std::string_view token, ScalarType type, char* dst) {
  if (type == ScalarType::FLOAT32) {
    float v = 0;
    if (!parse_number(token, v)) { return false; }
    std::memcpy(dst, &v, 4);
    return true;
  }
  if (type == ScalarType::FLOAT64) {
    double v = 0;
    if (!parse_number(token, v)) { return false; }
    std::memcpy(dst, &v, 8);
    return true;
  }
  std::int64_t v = 0;
  if (!parse_number(token, v)) { return false; }
  const std::uint32_t size = scalar_size(type);
  const bool is_signed =
      type == ScalarType::INT8 || type == ScalarType::INT16 || type == ScalarType::INT32;
  const int bits = static_cast<int>(size * 8);
  const std::int64_t lo = is_signed ? -(std::int64_t{1} << (bits - 1)) : 0;
  const std::int64_t hi =
      is_signed ? (std::int64_t{1} << (bits - 1)) - 1 : (std::int64_t{1} << bits) - 1;
  if (v < lo || v > hi) { return false; }
  const auto u = static_cast<std::uint64_t>(v);  // two's complement: the low bytes are the value
  std::memcpy(dst, &u, size);
  return true;
}

Result<void, IoError> parse_ascii_line(std::string_view line, std::span<std::string_view> tokens,
                                       const PcdHeader& h, char* record, std::string_view name,
                                       std::size_t line_no) {
  bool more = false;
  const std::size_t n = split_ws(line, tokens, more);
  const std::size_t expected = tokens.size();
  auto fail = [&](IoError::Code c, const std::string& what) {
    return err(IoError{c, std::string(name) + ": line " + std::to_string(line_no) + ": " + what});
  };
  if (more || n != expected) {
    return fail(IoError::Code::SIZE_MISMATCH, "expected " + std::to_string(expected) +
                                                  " values, found " +
                                                  (more ? "more" : std::to_string(n)));
  }
  std::size_t t = 0;
  for (const PointField& f : h.fields) {
    const std::uint32_t size = scalar_size(f.type);
    for (std::uint32_t c = 0; c < f.count; ++c, ++t) {
      if (!store_token(tokens[t], f.type, record + f.offset + c * size)) {
        return fail(
            IoError::Code::BAD_NUMBER,
            "'" + std::string(tokens[t]) + "' is not a valid value for field '" + f.name + "'");
      }
    }
  }
  return {};
}

Result<void, IoError> read_ascii(std::span<const char> bytes, const PcdHeader& h,
                                 std::string_view name, kernels::PointCloud& cloud) {
  std::size_t per_point = 0;
  for (const PointField& f : h.fields) { per_point += f.count; }
  const std::size_t have = bytes.size() - h.data_offset;
  if (h.points * per_point > have / 2 + 1) {  // every value takes a character and a separator
    return err(at_byte(IoError::Code::TRUNCATED, name, bytes.size(),
                       "ascii data of " + std::to_string(have) + " bytes cannot hold " +
                           std::to_string(h.points) + " points"));
  }
  std::vector<char> records(h.points * h.point_size());
  std::vector<std::string_view> tokens(per_point);
  LineCursor cursor(bytes, h.data_offset, h.data_line);
  std::string_view line;
  for (std::uint64_t i = 0; i < h.points; ++i) {
    bool got = false;
    while ((got = cursor.next(line)) && line.find_first_not_of(" \t") == std::string_view::npos) {}
    if (!got) {
      return err(IoError{IoError::Code::TRUNCATED,
                         std::string(name) + ": line " + std::to_string(cursor.line_number()) +
                             ": file ends after " + std::to_string(i) + " of " +
                             std::to_string(h.points) + " points"});
    }
    auto r = parse_ascii_line(line, tokens, h, records.data() + i * h.point_size(), name,
                              cursor.line_number());
    if (!r) { return err(r.error()); }
  }
  shape(h, cloud);
  decode_records(records, h.fields, h.point_size(), cloud);
  return {};
}

}  // namespace

Result<kernels::PointCloud, IoError> read_pcd_buffer(std::span<const char> bytes,
                                                     std::string_view name) {
  auto header_result = parse_pcd_header(bytes, name);
  if (!header_result) { return err(header_result.error()); }
  const PcdHeader& h = *header_result;
  kernels::PointCloud cloud;
  Result<void, IoError> body_result;
  switch (h.encoding) {
    case PcdEncoding::BINARY:
      body_result = read_binary(bytes, h, name, cloud);
      break;
    case PcdEncoding::BINARY_COMPRESSED:
      body_result = read_compressed(bytes, h, name, cloud);
      break;
    case PcdEncoding::ASCII:
      body_result = read_ascii(bytes, h, name, cloud);
      break;
  }
  if (!body_result) { return err(body_result.error()); }
  cloud.info.viewpoint = h.viewpoint;
  return cloud;
}

Result<kernels::PointCloud, IoError> read_pcd(const std::filesystem::path& path) {
  auto bytes_result = read_file_bytes(path);
  if (!bytes_result) { return err(bytes_result.error()); }
  return read_pcd_buffer(*bytes_result, path.string());
}

Result<PcdHeader, IoError> read_pcd_header(const std::filesystem::path& path) {
  auto bytes_result = read_file_bytes(path);
  if (!bytes_result) { return err(bytes_result.error()); }
  return parse_pcd_header(*bytes_result, path.string());
}

}  // namespace orthoflow::formats
