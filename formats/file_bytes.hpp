#pragma once
/// @file
/// @brief Whole-file reading and atomic whole-file writing with IoError reporting.
#include <filesystem>
#include <string_view>
#include <vector>

#include "core/input_limit.hpp"
#include "core/result.hpp"
#include "formats/io_error.hpp"

namespace orthoflow::formats {

/// @brief Reads the whole file, at most @p max_bytes of it: a longer file (or an endless one such
/// as /dev/zero) is TOO_LARGE, never an allocation without bound. Errors name the path and the
/// reason.
[[nodiscard]] Result<std::vector<char>, IoError> read_file_bytes(
    const std::filesystem::path& path, std::size_t max_bytes = core::max_input_bytes());

/// @brief Writes @p bytes to a temporary file beside @p path, then renames it over @p path,
/// so that readers never see a half-written file.
[[nodiscard]] Result<void, IoError> write_file_atomically(const std::filesystem::path& path,
                                                          std::string_view bytes);

}  // namespace orthoflow::formats
