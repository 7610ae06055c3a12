#pragma once
/// @file
/// @brief Whole-file reading and atomic whole-file writing with IoError reporting.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/input_limit.hpp"
#include "core/result.hpp"
#include "formats/io_error.hpp"

namespace orthoflow::formats {

/// @brief Reads the whole regular file, at most @p max_bytes of it (core/regular_file.hpp): a
/// longer file is TOO_LARGE, never an allocation without bound; a FIFO, socket or device (such as
/// /dev/zero) is OPEN_FAILED at once, never waited on. Errors name the path and the reason.
[[nodiscard]] Result<std::vector<char>, IoError> read_file_bytes(
    const std::filesystem::path& path, std::size_t max_bytes = core::max_input_bytes());

/// @brief The reason in a read_file_bytes error on @p path: its message without the leading
/// "<path>: " (for callers that name the file their own way).
[[nodiscard]] std::string read_failure_reason(const IoError& error,
                                              const std::filesystem::path& path);
/// @brief Writes @p bytes as the whole of @p path (core::write_whole_file): a regular file through
/// a temporary file renamed over it, so readers never see half of it; a device or FIFO such as
/// /dev/stdout or /dev/full is written into, never replaced, and a refused write is an error.
[[nodiscard]] Result<void, IoError> write_file_atomically(const std::filesystem::path& path,
                                                          std::string_view bytes);

}  // namespace orthoflow::formats
