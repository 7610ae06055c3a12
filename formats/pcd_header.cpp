#include "formats/pcd_header.hpp"

#include <algorithm>
#include <sstream>

#include "formats/text_scan.hpp"

namespace orthoflow::formats {
namespace {

/// Everything the keyword lines declare, before cross-checks.
struct RawHeader {
  std::vector<std::string> names;
  std::vector<std::uint32_t> sizes;
  std::vector<char> types;
  std::vector<std::uint32_t> counts;
  std::uint64_t width = 0;
  std::uint64_t height = 1;
  std::uint64_t points = 0;
  bool has_width = false;
  bool has_points = false;
};

IoError error_at(IoError::Code code, std::string_view name, std::size_t line,
                 const std::string& what) {
  return IoError{code, std::string(name) + ": line " + std::to_string(line) + ": " + what};
}

std::vector<std::string_view> tokens_of(std::string_view line) {
  std::vector<std::string_view> tokens(line.size() / 2 + 1);
  bool more = false;
  tokens.resize(split_ws(line, tokens, more));
  return tokens;
}

template <class T>
bool parse_all(std::span<const std::string_view> tokens, std::vector<T>& out) {
  out.clear();
  for (std::string_view t : tokens) {
    T v{};
    if (!parse_number(t, v)) { return false; }
    out.push_back(v);
  }
  return true;
}

Result<ScalarType, IoError> scalar_type(char type, std::uint32_t size, const std::string& field,
                                        std::string_view name, std::size_t line) {
  if (type == 'F' && size == 4) { return ScalarType::FLOAT32; }
  if (type == 'F' && size == 8) { return ScalarType::FLOAT64; }
  if ((type == 'I' || type == 'U') && (size == 1 || size == 2 || size == 4)) {
    const int log2 = (size == 1) ? 0 : (size == 2 ? 1 : 2);
    const int base = (type == 'I') ? 1 : 2;  // INT8 = 1, UINT8 = 2, then steps of 2
    return static_cast<ScalarType>(base + 2 * log2);
  }
  return err(error_at(IoError::Code::UNSUPPORTED, name, line,
                      "field '" + field + "' has unsupported TYPE " + std::string(1, type) +
                          " SIZE " + std::to_string(size)));
}

/// Applies one keyword line to @p raw; returns false with @p error set when the line is bad.
Result<void, IoError> apply_line(std::span<const std::string_view> tok, RawHeader& raw,
                                 PcdHeader& header, std::string_view name, std::size_t line) {
  const std::string_view key = tok[0];
  const auto args = tok.subspan(1);
  auto bad = [&](const std::string& what) {
    return err(error_at(IoError::Code::BAD_HEADER, name, line, what));
  };
  if (key == "VERSION") {
    header.version = args.empty() ? "" : std::string(args[0]);
  } else if (key == "FIELDS" || key == "COLUMNS") {
    raw.names.assign(args.begin(), args.end());
    if (raw.names.empty()) { return bad("FIELDS lists no field"); }
  } else if (key == "SIZE") {
    if (!parse_all(args, raw.sizes)) { return bad("SIZE values must be integers"); }
  } else if (key == "TYPE") {
    raw.types.clear();
    for (std::string_view t : args) {
      if (t.size() != 1 || (t[0] != 'F' && t[0] != 'I' && t[0] != 'U')) {
        return bad("TYPE must be F, I or U");
      }
      raw.types.push_back(t[0]);
    }
  } else if (key == "COUNT") {
    if (!parse_all(args, raw.counts)) { return bad("COUNT values must be integers"); }
  } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
    std::uint64_t v = 0;
    if (args.size() != 1 || !parse_number(args[0], v)) {
      return bad(std::string(key) + " needs one integer");
    }
    if (key == "WIDTH") {
      raw.width = v;
      raw.has_width = true;
    }
    if (key == "HEIGHT") { raw.height = v; }
    if (key == "POINTS") {
      raw.points = v;
      raw.has_points = true;
    }
  } else if (key == "VIEWPOINT") {
    std::vector<float> v;
    if (args.size() != 7 || !parse_all(args, v)) { return bad("VIEWPOINT needs 7 numbers"); }
    header.viewpoint.origin = {v[0], v[1], v[2]};
    header.viewpoint.orientation = {v[3], v[4], v[5], v[6]};
  } else {
    return bad("unknown header keyword '" + std::string(key) + "'");
  }
  return {};
}

Result<void, IoError> build_fields(const RawHeader& raw, PcdHeader& header, std::string_view name,
                                   std::size_t line) {
  const std::size_t n = raw.names.size();
  auto fail = [&](IoError::Code c, const std::string& what) {
    return err(error_at(c, name, line, what));
  };
  if (n == 0) { return fail(IoError::Code::BAD_HEADER, "no FIELDS line"); }
  if (raw.sizes.size() != n || raw.types.size() != n) {
    return fail(IoError::Code::BAD_HEADER,
                "FIELDS, SIZE and TYPE list different numbers of entries");
  }
  if (!raw.counts.empty() && raw.counts.size() != n) {
    return fail(IoError::Code::BAD_HEADER, "FIELDS and COUNT list different numbers of entries");
  }
  std::uint64_t offset = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t count = raw.counts.empty() ? 1U : raw.counts[i];
    if (count == 0) {
      return fail(IoError::Code::BAD_HEADER, "field '" + raw.names[i] + "' has COUNT 0");
    }
    auto type_result = scalar_type(raw.types[i], raw.sizes[i], raw.names[i], name, line);
    if (!type_result) { return err(type_result.error()); }
    const bool duplicate = std::count(raw.names.begin(), raw.names.end(), raw.names[i]) > 1;
    if (duplicate && raw.names[i] != "_") {
      return fail(IoError::Code::BAD_HEADER, "field '" + raw.names[i] + "' is declared twice");
    }
    offset += static_cast<std::uint64_t>(raw.sizes[i]) * count;
    if (offset > MAX_PCD_RECORD_BYTES) {
      return fail(IoError::Code::TOO_LARGE, "a point record exceeds 64 KiB");
    }
    const auto field_offset =
        static_cast<std::uint32_t>(offset - static_cast<std::uint64_t>(raw.sizes[i]) * count);
    header.fields.push_back(PointField{raw.names[i], field_offset, *type_result, count});
  }
  for (const char* axis : {"x", "y", "z"}) {
    if (std::find(raw.names.begin(), raw.names.end(), axis) == raw.names.end()) {
      return fail(IoError::Code::BAD_HEADER, std::string("no '") + axis + "' field");
    }
  }
  return {};
}

Result<void, IoError> check_counts(const RawHeader& raw, PcdHeader& header, std::string_view name,
                                   std::size_t line) {
  auto fail = [&](IoError::Code c, const std::string& what) {
    return err(error_at(c, name, line, what));
  };
  if (!raw.has_width) { return fail(IoError::Code::BAD_HEADER, "no WIDTH line"); }
  if (raw.width > MAX_PCD_POINTS || raw.height > MAX_PCD_POINTS || raw.points > MAX_PCD_POINTS) {
    return fail(IoError::Code::TOO_LARGE, "more than 2^31 points declared");
  }
  const std::uint64_t wh = raw.width * raw.height;
  const std::uint64_t points = raw.has_points ? raw.points : wh;
  if (points != wh) {
    return fail(IoError::Code::SIZE_MISMATCH,
                "POINTS " + std::to_string(points) + " != WIDTH x HEIGHT " +
                    std::to_string(raw.width) + " x " + std::to_string(raw.height));
  }
  if (points > MAX_PCD_POINTS) {
    return fail(IoError::Code::TOO_LARGE, "more than 2^31 points declared");
  }
  header.width = static_cast<std::uint32_t>(raw.width);
  header.height = static_cast<std::uint32_t>(raw.height);
  header.points = points;
  return {};
}

}  // namespace

const char* to_string(PcdEncoding encoding) noexcept {
  switch (encoding) {
    case PcdEncoding::ASCII:
      return "ascii";
    case PcdEncoding::BINARY:
      return "binary";
    case PcdEncoding::BINARY_COMPRESSED:
      return "binary_compressed";
  }
  return "unknown";
}

Result<PcdHeader, IoError> parse_pcd_header(std::span<const char> bytes, std::string_view name) {
  PcdHeader header;
  RawHeader raw;
  LineCursor cursor(bytes);
  std::string_view line;
  while (cursor.next(line)) {
    const std::vector<std::string_view> tok = tokens_of(line);
    if (tok.empty() || tok[0].front() == '#') { continue; }
    if (tok[0] == "DATA") {
      const std::size_t at = cursor.line_number();
      if (tok.size() != 2) {
        return err(error_at(IoError::Code::BAD_HEADER, name, at, "DATA needs one encoding"));
      }
      if (tok[1] == "ascii") {
        header.encoding = PcdEncoding::ASCII;
      } else if (tok[1] == "binary") {
        header.encoding = PcdEncoding::BINARY;
      } else if (tok[1] == "binary_compressed") {
        header.encoding = PcdEncoding::BINARY_COMPRESSED;
      } else {
        return err(error_at(IoError::Code::UNSUPPORTED, name, at,
                            "unknown DATA encoding '" + std::string(tok[1]) + "'"));
      }
      if (auto r = build_fields(raw, header, name, at); !r) { return err(r.error()); }
      if (auto r = check_counts(raw, header, name, at); !r) { return err(r.error()); }
      header.data_offset = cursor.offset();
      header.data_line = at + 1;
      return header;
    }
    if (auto r = apply_line(tok, raw, header, name, cursor.line_number()); !r) {
      return err(r.error());
    }
  }
  return err(IoError{IoError::Code::BAD_HEADER,
                     std::string(name) + ": no DATA line (not a PCD file, or cut short)"});
}

std::string format_pcd_header(const kernels::PointCloud& cloud, std::span<const PointField> fields,
                              PcdEncoding encoding) {
  std::ostringstream out;
  out << "# .PCD v0.7 - Point Cloud Data file format (written by orthoflow)\nVERSION 0.7\nFIELDS";
  for (const PointField& f : fields) { out << ' ' << f.name; }
  out << "\nSIZE";
  for (const PointField& f : fields) { out << ' ' << scalar_size(f.type); }
  out << "\nTYPE";
  for (const PointField& f : fields) {
    out << ' ' << (f.type == ScalarType::FLOAT32 || f.type == ScalarType::FLOAT64 ? 'F' : 'U');
  }
  out << "\nCOUNT";
  for (const PointField& f : fields) { out << ' ' << f.count; }
  const kernels::Viewpoint& v = cloud.info.viewpoint;
  out.precision(9);
  out << "\nWIDTH " << cloud.width() << "\nHEIGHT " << cloud.height() << "\nVIEWPOINT "
      << v.origin[0] << ' ' << v.origin[1] << ' ' << v.origin[2] << ' ' << v.orientation[0] << ' '
      << v.orientation[1] << ' ' << v.orientation[2] << ' ' << v.orientation[3] << "\nPOINTS "
      << cloud.size() << "\nDATA " << to_string(encoding) << '\n';
  return out.str();
}

}  // namespace orthoflow::formats
