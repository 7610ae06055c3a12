#pragma once
/// @file
/// @brief 16-bit greyscale PNG depth images (the TUM RGB-D benchmark's `depth/*.png`, and what
/// OpenNI and ROS tools write): read and written with libpng. The reader is strict: anything but a
/// 16-bit, single-channel image of the expected size is an error naming the file, never a frame.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "core/result.hpp"
#include "formats/io_error.hpp"

namespace orthoflow::formats {

/// @brief Decodes a 16-bit greyscale PNG held in memory into @p out (row-major, host order),
/// which must hold exactly @p width x @p height values: a different size, bit depth or colour type
/// is UNSUPPORTED or SIZE_MISMATCH, a damaged stream CORRUPT_DATA or TRUNCATED. (The reader's
/// core; fuzzed.) @note Allocates libpng's state and one row-pointer table.
[[nodiscard]] Result<void, IoError> parse_png_depth16(std::span<const char> bytes,
                                                      const std::string& name, std::uint32_t width,
                                                      std::uint32_t height,
                                                      std::span<std::uint16_t> out);

/// @brief Writes @p values (row-major, @p width x @p height) as a 16-bit greyscale PNG,
/// atomically.
[[nodiscard]] Result<void, IoError> write_png_depth16(const std::filesystem::path& path,
                                                      std::span<const std::uint16_t> values,
                                                      std::uint32_t width, std::uint32_t height);

}  // namespace orthoflow::formats
