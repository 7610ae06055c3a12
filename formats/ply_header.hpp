#pragma once
// PLY header model shared by the PLY reader's header and body parts (internal to formats/).
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"
#include "formats/io_error.hpp"
#include "formats/point_fields.hpp"

namespace orthoflow::formats {

enum class PlyFormat : std::uint8_t { ASCII, BINARY_LE, BINARY_BE };

struct PlyProperty {
  std::string name;
  ScalarType type = ScalarType::FLOAT32;  ///< the value type (the item type of a list)
  bool is_list = false;
  ScalarType count_type = ScalarType::UINT8;  ///< type of a list's length prefix
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::ASCII;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;
  std::size_t data_line = 0;
};

/// Most vertices orthoflow accepts in one model.
inline constexpr std::uint64_t MAX_PLY_VERTICES = 1ULL << 31;

/// Parses "ply" ... "end_header"; errors name the line.
[[nodiscard]] Result<PlyHeader, IoError> parse_ply_header(std::span<const char> bytes,
                                                          std::string_view name);

}  // namespace orthoflow::formats
