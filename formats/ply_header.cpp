#include "formats/ply_header.hpp"

#include "formats/text_scan.hpp"

namespace orthoflow::formats {
namespace {

bool ply_type(std::string_view t, ScalarType& out) {
  struct Name {
    std::string_view a, b;
    ScalarType type;
  };
  static constexpr Name NAMES[] = {
      {"char", "int8", ScalarType::INT8},        {"uchar", "uint8", ScalarType::UINT8},
      {"short", "int16", ScalarType::INT16},     {"ushort", "uint16", ScalarType::UINT16},
      {"int", "int32", ScalarType::INT32},       {"uint", "uint32", ScalarType::UINT32},
      {"float", "float32", ScalarType::FLOAT32}, {"double", "float64", ScalarType::FLOAT64}};
  for (const Name& n : NAMES) {
    if (t == n.a || t == n.b) {
      out = n.type;
      return true;
    }
  }
  return false;
}

Result<void, IoError> apply(std::span<const std::string_view> tok, PlyHeader& h, bool& has_format) {
  const std::string_view key = tok[0];
  if (key == "comment" || key == "obj_info") { return {}; }
  auto bad = [](IoError::Code c, const std::string& what) { return err(IoError{c, what}); };
  if (key == "format") {
    if (tok.size() != 3 || tok[2] != "1.0") {
      return bad(IoError::Code::BAD_HEADER, "format needs a type and 1.0");
    }
    if (tok[1] == "ascii") {
      h.format = PlyFormat::ASCII;
    } else if (tok[1] == "binary_little_endian") {
      h.format = PlyFormat::BINARY_LE;
    } else if (tok[1] == "binary_big_endian") {
      h.format = PlyFormat::BINARY_BE;
    } else {
      return bad(IoError::Code::UNSUPPORTED, "unknown format '" + std::string(tok[1]) + "'");
    }
    has_format = true;
  } else if (key == "element") {
    PlyElement e;
    if (tok.size() != 3 || !parse_number(tok[2], e.count)) {
      return bad(IoError::Code::BAD_HEADER, "element needs a name and a count");
    }
    if (e.count > MAX_PLY_VERTICES) {
      return bad(IoError::Code::TOO_LARGE, "element count above 2^31");
    }
    e.name = std::string(tok[1]);
    h.elements.push_back(std::move(e));
  } else if (key == "property") {
    if (h.elements.empty()) {
      return bad(IoError::Code::BAD_HEADER, "property before any element");
    }
    PlyProperty p;
    const bool list = tok.size() == 5 && tok[1] == "list";
    if (!list && tok.size() != 3) {
      return bad(IoError::Code::BAD_HEADER, "property needs a type and a name");
    }
    if (list && (!ply_type(tok[2], p.count_type) || !ply_type(tok[3], p.type))) {
      return bad(IoError::Code::UNSUPPORTED, "unknown list property type");
    }
    if (list && (p.count_type == ScalarType::FLOAT32 || p.count_type == ScalarType::FLOAT64)) {
      return bad(IoError::Code::UNSUPPORTED, "a list length must have an integer type");
    }
    if (!list && !ply_type(tok[1], p.type)) {
      return bad(IoError::Code::UNSUPPORTED, "unknown property type '" + std::string(tok[1]) + "'");
    }
    p.is_list = list;
    p.name = std::string(tok[tok.size() - 1]);
    h.elements.back().properties.push_back(std::move(p));
  } else {
    return bad(IoError::Code::BAD_HEADER, "unknown header keyword '" + std::string(key) + "'");
  }
  return {};
}

}  // namespace

Result<PlyHeader, IoError> parse_ply_header(std::span<const char> bytes, std::string_view name) {
  PlyHeader h;
  LineCursor cursor(bytes);
  std::string_view line;
  auto at = [&](IoError e) {
    e.message =
        std::string(name) + ": line " + std::to_string(cursor.line_number()) + ": " + e.message;
    return err(std::move(e));
  };
  if (!cursor.next(line) || line != "ply") {
    return at(IoError{IoError::Code::BAD_HEADER, "not a PLY file (no 'ply' magic line)"});
  }
  bool has_format = false;
  std::vector<std::string_view> tok(8);
  while (cursor.next(line)) {
    bool more = false;
    tok.resize(8);
    tok.resize(split_ws(line, tok, more));
    if (tok.empty()) { continue; }
    if (tok[0] == "end_header") {
      if (!has_format) { return at(IoError{IoError::Code::BAD_HEADER, "no format line"}); }
      h.data_offset = cursor.offset();
      h.data_line = cursor.line_number() + 1;
      return h;
    }
    if (more && tok[0] != "comment" && tok[0] != "obj_info") {
      return at(IoError{IoError::Code::BAD_HEADER, "too many words"});
    }
    if (auto r = apply(tok, h, has_format); !r) { return at(r.error()); }
  }
  return err(IoError{IoError::Code::BAD_HEADER, std::string(name) + ": no end_header line"});
}

}  // namespace orthoflow::formats
