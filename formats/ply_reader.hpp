#pragma once
/// @file
/// @brief Reading PLY object models (ascii, binary_little_endian, binary_big_endian).
/// Kept: the vertex element's x, y, z (float or double), red/green/blue(/alpha) as packed RGB
/// (alpha 255 when absent) and nx/ny/nz as normals. Faces and any other element, including list
/// properties, are parsed and skipped. The cloud is unorganized.
#include <filesystem>
#include <span>
#include <string_view>

#include "core/result.hpp"
#include "formats/io_error.hpp"
#include "kernels/point_cloud.hpp"

namespace orthoflow::formats {

/// @brief Reads a PLY file. @note Thread-safe (no shared state).
[[nodiscard]] Result<kernels::PointCloud, IoError> read_ply(const std::filesystem::path& path);

/// @brief Reads PLY bytes held in memory; @p name prefixes error messages.
[[nodiscard]] Result<kernels::PointCloud, IoError> read_ply_buffer(
    std::span<const char> bytes, std::string_view name = "<memory>");

}  // namespace orthoflow::formats
