#pragma once
/// @file
/// @brief The one way the product writes a whole output file. A regular file (or a new one) is
/// written beside its place, synced and renamed over it, so a reader never sees half a file. A path
/// that names something else (/dev/stdout, /dev/null, /dev/full, a FIFO a person reads from) is
/// written into as it is, never replaced by a regular file, and a write it refuses (a full disk, a
/// closed pipe) is an error, never a silent success.
#include <filesystem>
#include <string>
#include <string_view>

#include "core/result.hpp"

namespace orthoflow::core {

/// @brief Writes @p bytes as the whole content of @p path; the error is "<path>: <reason>". With
/// @p synced, a regular file's bytes reach the disk (fsync) before it takes its place.
[[nodiscard]] Result<void, std::string> write_whole_file(const std::filesystem::path& path,
                                                         std::string_view bytes,
                                                         bool synced = false);

}  // namespace orthoflow::core
