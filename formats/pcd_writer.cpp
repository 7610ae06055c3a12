// PCD writer: one header, then packed records (binary), an LZF block of field-major data
// (binary_compressed, PCL's layout) or one text line per point (ascii).
#include <charconv>
#include <cstring>
#include <vector>

#include <lzf.h>

#include "core/assert.hpp"
#include "formats/file_bytes.hpp"
#include "formats/pcd_io.hpp"

namespace orthoflow::formats {
namespace {

void append_binary(const kernels::PointCloud& cloud, std::span<const PointField> fields,
                   std::string& out) {
  const std::size_t at = out.size();
  out.resize(at + cloud.size() * packed_size(fields));
  encode_records(cloud, fields, std::span<char>(out.data() + at, out.size() - at));
}

void append_compressed(const kernels::PointCloud& cloud, std::span<const PointField> fields,
                       std::string& out) {
  const std::size_t n = cloud.size();
  std::vector<char> soa(n * packed_size(fields));
  for (const PointField& f : n == 0 ? std::span<const PointField>{} : fields) {
    encode_field(cloud, f, soa.data() + n * f.offset, f.bytes());
  }
  // LZF may grow incompressible data slightly: one control byte per 32 literals.
  std::vector<char> packed(soa.size() + soa.size() / 16 + 64);
  unsigned packed_size_bytes = 0;
  if (!soa.empty()) {
    packed_size_bytes = lzf_compress(soa.data(), static_cast<unsigned>(soa.size()), packed.data(),
                                     static_cast<unsigned>(packed.size()));
    OF_ENFORCE(packed_size_bytes > 0, "LZF output buffer too small");
  }
  const auto sizes =
      std::array<std::uint32_t, 2>{packed_size_bytes, static_cast<std::uint32_t>(soa.size())};
  out.append(reinterpret_cast<const char*>(sizes.data()), sizeof(sizes));
  out.append(packed.data(), packed_size_bytes);
}

void append_number(float v, std::string& out) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);  // shortest text that reads back exactly
  out.append(buf, r.ptr);
}

void append_number(std::uint32_t v, std::string& out) {
  char buf[16];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out.append(buf, r.ptr);
}

void append_ascii(const kernels::PointCloud& cloud, std::span<const PointField> fields,
                  std::string& out) {
  struct Column {
    std::span<const float> floats;
    std::span<const std::uint32_t> words;
  };
  std::vector<Column> columns;
  for (const PointField& f : fields) {
    const FieldTarget t = field_target(f.name);
    columns.push_back(t == FieldTarget::RGB     ? Column{{}, cloud.rgb()}
                      : t == FieldTarget::LABEL ? Column{{}, cloud.label()}
                                                : Column{float_buffer(cloud, t), {}});
  }
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (std::size_t k = 0; k < columns.size(); ++k) {
      if (k > 0) { out.push_back(' '); }
      if (columns[k].words.empty()) {
        append_number(columns[k].floats[i], out);
      } else {
        append_number(columns[k].words[i], out);
      }
    }
    out.push_back('\n');
  }
}

}  // namespace

std::string encode_pcd(const kernels::PointCloud& cloud, PcdEncoding encoding) {
  const std::vector<PointField> fields = fields_for(cloud);
  std::string out = format_pcd_header(cloud, fields, encoding);
  switch (encoding) {
    case PcdEncoding::BINARY:
      append_binary(cloud, fields, out);
      break;
    case PcdEncoding::BINARY_COMPRESSED:
      append_compressed(cloud, fields, out);
      break;
    case PcdEncoding::ASCII:
      append_ascii(cloud, fields, out);
      break;
  }
  return out;
}

Result<void, IoError> write_pcd(const kernels::PointCloud& cloud, const std::filesystem::path& path,
                                PcdEncoding encoding) {
  return write_file_atomically(path, encode_pcd(cloud, encoding));
}

}  // namespace orthoflow::formats
