#pragma once
/// @file
/// @brief The PCD header (versions 0.5 to 0.7): what a file declares before its data.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"
#include "formats/io_error.hpp"
#include "formats/point_fields.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::formats {

/// @brief How the data section of a PCD file is stored.
enum class PcdEncoding : std::uint8_t { ASCII, BINARY, BINARY_COMPRESSED };

/// @brief "ascii", "binary" or "binary_compressed".
[[nodiscard]] const char* to_string(PcdEncoding encoding) noexcept;

/// @brief Everything a PCD header declares.
struct PcdHeader {
  std::string version;             ///< as written ("0.7", ".7", ...); empty when absent
  std::vector<PointField> fields;  ///< offsets packed in declaration order
  std::uint32_t width = 0;
  std::uint32_t height = 1;
  std::uint64_t points = 0;
  kernels::Viewpoint viewpoint{};
  PcdEncoding encoding = PcdEncoding::BINARY;
  std::size_t data_offset = 0;  ///< byte offset of the first data byte
  std::size_t data_line = 0;    ///< line number of the first data line (ASCII data)
  [[nodiscard]] std::uint32_t point_size() const noexcept { return packed_size(fields); }
};

/// @brief Largest point count and record size orthoflow accepts; beyond them a file is TOO_LARGE.
inline constexpr std::uint64_t MAX_PCD_POINTS = 1ULL << 31;
inline constexpr std::uint32_t MAX_PCD_RECORD_BYTES = 1U << 16;

/// @brief Parses the header at the start of @p bytes; @p name prefixes every error message.
/// Checks: known keywords, FIELDS/SIZE/TYPE/COUNT agree, supported types, x/y/z present, no
/// duplicate field, POINTS == WIDTH x HEIGHT, sizes within the limits above, a DATA line.
[[nodiscard]] Result<PcdHeader, IoError> parse_pcd_header(std::span<const char> bytes,
                                                          std::string_view name);

/// @brief The header text orthoflow writes for @p cloud with @p fields (ends with the DATA line).
[[nodiscard]] std::string format_pcd_header(const kernels::PointCloud& cloud,
                                            std::span<const PointField> fields,
                                            PcdEncoding encoding);

}  // namespace orthoflow::formats
