// PLY body: one pass over the elements in header order; the vertex element fills the cloud,
// every other element (faces, edges, ...) is read past, list properties included.
#include "formats/ply_reader.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <type_traits>
#include <vector>

#include "formats/file_bytes.hpp"
#include "formats/ply_header.hpp"
#include "formats/text_scan.hpp"

namespace orthoflow::formats {
namespace {

/// Longest list orthoflow reads past (a face with more corners is surely corrupt).
constexpr std::uint64_t MAX_LIST_LENGTH = 1U << 16;

double as_double(const unsigned char* p, ScalarType t) {
  auto get = [p]<class T>(T) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  };
  switch (t) {
    case ScalarType::INT8:
      return get(std::int8_t{});
    case ScalarType::UINT8:
      return get(std::uint8_t{});
    case ScalarType::INT16:
      return get(std::int16_t{});
    case ScalarType::UINT16:
      return get(std::uint16_t{});
    case ScalarType::INT32:
      return get(std::int32_t{});
    case ScalarType::UINT32:
      return get(std::uint32_t{});
    case ScalarType::FLOAT32:
      return get(float{});
    case ScalarType::FLOAT64:
      return get(double{});
  }
  return 0.0;
}

/// What reading one value gave.
enum class Read : std::uint8_t { OK, END, NOT_A_NUMBER };

/// Whether an integer value fits the declared PLY type.
bool fits(double v, ScalarType t) {
  switch (t) {
    case ScalarType::INT8:
      return v >= -128 && v <= 127;
    case ScalarType::UINT8:
      return v >= 0 && v <= 255;
    case ScalarType::INT16:
      return v >= -32768 && v <= 32767;
    case ScalarType::UINT16:
      return v >= 0 && v <= 65535;
    case ScalarType::INT32:
      return v >= -2147483648.0 && v <= 2147483647.0;
    case ScalarType::UINT32:
      return v >= 0 && v <= 4294967295.0;
    default:
      return true;
  }
}

class BinarySource {
 public:
  BinarySource(std::span<const char> bytes, std::size_t offset, bool big_endian)
      : bytes_(bytes), pos_(offset), swap_(big_endian) {}
  bool begin_instance() { return true; }
  bool end_instance() { return true; }
  Read read(ScalarType t, double& v) {
    const std::size_t n = scalar_size(t);
    if (bytes_.size() - pos_ < n) { return Read::END; }
    std::array<unsigned char, 8> buf{};
    std::memcpy(buf.data(), bytes_.data() + pos_, n);
    if (swap_) { std::reverse(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)); }
    v = as_double(buf.data(), t);
    pos_ += n;
    return Read::OK;
  }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - pos_; }
  [[nodiscard]] std::string where() const { return "byte " + std::to_string(pos_); }

 private:
  std::span<const char> bytes_;
  std::size_t pos_;
  bool swap_;
};

class AsciiSource {
 public:
  AsciiSource(std::span<const char> bytes, std::size_t offset, std::size_t line)
      : cursor_(bytes, offset, line), remaining_(bytes.size() - offset) {}
  bool begin_instance() {
    std::string_view line;
    bool got = false;
    while ((got = cursor_.next(line)) && line.find_first_not_of(" \t") == std::string_view::npos) {}
    if (!got) { return false; }
    tokens_.resize(line.size() / 2 + 1);
    bool more = false;
    tokens_.resize(split_ws(line, tokens_, more));
    next_ = 0;
    return true;
  }
  bool end_instance() const { return next_ == tokens_.size(); }
  Read read(ScalarType t, double& v) {
    if (next_ >= tokens_.size()) { return Read::END; }
    const std::string_view tok = tokens_[next_++];
    if (t == ScalarType::FLOAT32 || t == ScalarType::FLOAT64) {
      return parse_number(tok, v) ? Read::OK : Read::NOT_A_NUMBER;
    }
    std::int64_t i = 0;
    if (!parse_number(tok, i)) { return Read::NOT_A_NUMBER; }
    v = static_cast<double>(i);
    return fits(v, t) ? Read::OK : Read::NOT_A_NUMBER;
  }
  [[nodiscard]] std::size_t remaining() const { return remaining_; }
  [[nodiscard]] std::string where() const {
    return "line " + std::to_string(cursor_.line_number());
  }

 private:
  LineCursor cursor_;
  std::size_t remaining_;
  std::vector<std::string_view> tokens_;
  std::size_t next_ = 0;
};

enum class Slot : std::uint8_t { NONE, X, Y, Z, NX, NY, NZ, R, G, B, A };

Slot slot_of(const std::string& n) {
  static const std::pair<const char*, Slot> NAMES[] = {
      {"x", Slot::X},    {"y", Slot::Y},    {"z", Slot::Z},   {"nx", Slot::NX},
      {"ny", Slot::NY},  {"nz", Slot::NZ},  {"red", Slot::R}, {"green", Slot::G},
      {"blue", Slot::B}, {"alpha", Slot::A}};
  for (const auto& [name, slot] : NAMES) {
    if (n == name) { return slot; }
  }
  return Slot::NONE;
}

/// A colour channel clamped to 0..255 (a float property may hold NaN or anything else).
std::uint32_t channel(double v) {
  return v >= 0.0 ? static_cast<std::uint32_t>(std::min(v, 255.0)) : 0U;
}

void store(kernels::PointCloud& c, std::size_t i, const std::array<double, 11>& v) {
  c.x()[i] = static_cast<float>(v[1]);
  c.y()[i] = static_cast<float>(v[2]);
  c.z()[i] = static_cast<float>(v[3]);
  if (c.has(kernels::Field::NORMALS)) {
    c.normal_x()[i] = static_cast<float>(v[4]);
    c.normal_y()[i] = static_cast<float>(v[5]);
    c.normal_z()[i] = static_cast<float>(v[6]);
  }
  if (c.has(kernels::Field::RGB)) {
    c.rgb()[i] =
        (channel(v[10]) << 24) | (channel(v[7]) << 16) | (channel(v[8]) << 8) | channel(v[9]);
  }
}

/// Checks that the element's instances can fit in what is left before anything is allocated.
bool plausible(const PlyElement& e, std::size_t remaining, bool ascii) {
  std::uint64_t min_bytes = 0;
  for (const PlyProperty& p : e.properties) {
    min_bytes += p.is_list ? scalar_size(p.count_type) : scalar_size(p.type);
  }
  // ASCII: every instance is at least a line break, even with no property.
  if (ascii) { min_bytes = std::max<std::uint64_t>(1, 2 * e.properties.size()); }
  return min_bytes == 0 || e.count <= remaining / min_bytes;
}

template <class Source>
Result<void, IoError> read_element(Source& src, const PlyElement& e, bool is_vertex,
                                   kernels::PointCloud& cloud, std::string_view name) {
  auto fail = [&](IoError::Code c, const std::string& what) {
    return err(IoError{c, std::string(name) + ": " + src.where() + ": " + what});
  };
  // A binary element without properties occupies no bytes, whatever its count: nothing to walk (a
  // count of 10^9 must not mean 10^9 empty iterations; found by fuzz_ply_reader).
  if (e.properties.empty() && std::is_same_v<Source, BinarySource>) { return {}; }
  std::vector<Slot> slots;
  for (const PlyProperty& p : e.properties) {
    slots.push_back(is_vertex && !p.is_list ? slot_of(p.name) : Slot::NONE);
  }
  for (std::uint64_t i = 0; i < e.count; ++i) {
    std::array<double, 11> v{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 255};
    if (!src.begin_instance()) {
      return fail(IoError::Code::TRUNCATED, "file ends inside element '" + e.name + "'");
    }
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      double value = 0;
      const Read got = src.read(p.is_list ? p.count_type : p.type, value);
      if (got != Read::OK) {
        return fail(got == Read::END ? IoError::Code::TRUNCATED : IoError::Code::BAD_NUMBER,
                    "element '" + e.name + "' #" + std::to_string(i) + ", property '" + p.name +
                        "': " + (got == Read::END ? "ends early" : "not a valid value"));
      }
      if (p.is_list) {
        if (!(value >= 0.0 && value <= static_cast<double>(MAX_LIST_LENGTH))) {
          return fail(IoError::Code::CORRUPT_DATA, "list length out of range");
        }
        for (auto n = static_cast<std::uint64_t>(value); n > 0; --n) {
          double item = 0;
          if (src.read(p.type, item) != Read::OK) {
            return fail(IoError::Code::TRUNCATED,
                        "list of '" + p.name + "' ends early or holds a non-number");
          }
        }
      } else {
        v[static_cast<std::size_t>(slots[k])] = value;
      }
    }
    if (!src.end_instance()) {
      return fail(IoError::Code::SIZE_MISMATCH, "more values than the element declares");
    }
    if (is_vertex) { store(cloud, static_cast<std::size_t>(i), v); }
  }
  return {};
}

template <class Source>
Result<void, IoError> read_body(Source& src, const PlyHeader& h, kernels::PointCloud& cloud,
                                std::string_view name) {
  bool seen_vertex = false;
  for (const PlyElement& e : h.elements) {
    const bool is_vertex = e.name == "vertex" && !seen_vertex;
    if (!plausible(e, src.remaining(), h.format == PlyFormat::ASCII)) {
      return err(IoError{IoError::Code::TRUNCATED, std::string(name) + ": element '" + e.name +
                                                       "' declares " + std::to_string(e.count) +
                                                       " entries, more than the file holds"});
    }
    if (is_vertex) {
      seen_vertex = true;
      cloud.resize_unorganized(static_cast<std::size_t>(e.count));
      for (const PlyProperty& p : e.properties) {
        const Slot s = slot_of(p.name);
        if (s == Slot::NX || s == Slot::NY || s == Slot::NZ) {
          cloud.add_field(kernels::Field::NORMALS);
        }
        if (s == Slot::R || s == Slot::G || s == Slot::B) { cloud.add_field(kernels::Field::RGB); }
      }
    }
    if (auto r = read_element(src, e, is_vertex, cloud, name); !r) { return r; }
  }
  return {};
}

Result<void, IoError> check_vertex(const PlyHeader& h, std::string_view name) {
  for (const PlyElement& e : h.elements) {
    if (e.name != "vertex") { continue; }
    for (const char* axis : {"x", "y", "z"}) {
      const bool found =
          std::any_of(e.properties.begin(), e.properties.end(),
                      [axis](const PlyProperty& p) { return !p.is_list && p.name == axis; });
      if (!found) {
        return err(IoError{IoError::Code::BAD_HEADER,
                           std::string(name) + ": vertex has no '" + axis + "'"});
      }
    }
    return {};
  }
  return err(IoError{IoError::Code::BAD_HEADER, std::string(name) + ": no vertex element"});
}

}  // namespace

Result<kernels::PointCloud, IoError> read_ply_buffer(std::span<const char> bytes,
                                                     std::string_view name) {
  auto header_result = parse_ply_header(bytes, name);
  if (!header_result) { return err(header_result.error()); }
  const PlyHeader& h = *header_result;
  if (auto r = check_vertex(h, name); !r) { return err(r.error()); }
  kernels::PointCloud cloud;
  Result<void, IoError> body_result;
  if (h.format == PlyFormat::ASCII) {
    AsciiSource src(bytes, h.data_offset, h.data_line);
    body_result = read_body(src, h, cloud, name);
  } else {
    BinarySource src(bytes, h.data_offset, h.format == PlyFormat::BINARY_BE);
    body_result = read_body(src, h, cloud, name);
  }
  if (!body_result) { return err(body_result.error()); }
  return cloud;
}

Result<kernels::PointCloud, IoError> read_ply(const std::filesystem::path& path) {
  auto bytes_result = read_file_bytes(path);
  if (!bytes_result) { return err(bytes_result.error()); }
  return read_ply_buffer(*bytes_result, path.string());
}

}  // namespace orthoflow::formats
