#pragma once
/// @file
/// @brief Reading and writing PCD files (PCL's Point Cloud Data format, versions 0.5 to 0.7).
///
/// Reads DATA ascii, binary and binary_compressed (LZF) with any fields, sizes, types and counts.
/// Kept: x, y, z; rgb or rgba (packed 0xAARRGGBB bits, whether declared F 4 or U 4); label;
/// normal_x/y/z; width x height; VIEWPOINT. Other fields are read past and dropped.
/// Writes x y z as F 4, rgb as `rgba U 4` (PCL reads it back into PointXYZRGB(A) bit for bit),
/// label as U 4 and normals as F 4; ascii values use the shortest text that reads back exactly.
/// Bad input returns an IoError saying what and where; nothing is allocated beyond what the
/// file's own size can justify.
#include <filesystem>
#include <span>
#include <string_view>

#include "core/result.hpp"
#include "formats/io_error.hpp"
#include "formats/pcd_header.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::formats {

/// @brief Reads a PCD file. @note Thread-safe (no shared state).
[[nodiscard]] Result<kernels::PointCloud, IoError> read_pcd(const std::filesystem::path& path);

/// @brief Reads PCD bytes held in memory; @p name prefixes error messages.
[[nodiscard]] Result<kernels::PointCloud, IoError> read_pcd_buffer(
    std::span<const char> bytes, std::string_view name = "<memory>");

/// @brief Reads only the header of a PCD file (fields, sizes, encoding) without its data.
[[nodiscard]] Result<PcdHeader, IoError> read_pcd_header(const std::filesystem::path& path);

/// @brief Writes @p cloud; the file appears whole or not at all (written beside it, then renamed).
[[nodiscard]] Result<void, IoError> write_pcd(
    const kernels::PointCloud& cloud, const std::filesystem::path& path,
    PcdEncoding encoding = PcdEncoding::BINARY_COMPRESSED);

/// @brief The bytes write_pcd() would write.
[[nodiscard]] std::string encode_pcd(const kernels::PointCloud& cloud, PcdEncoding encoding);

}  // namespace orthoflow::formats
