#pragma once
/// @file
/// @brief The one way the product reads a whole input file: a regular file of bounded size,
/// opened without blocking. A FIFO, a socket or a device (/dev/zero, a terminal) is refused at
/// once, never waited on or read without end; a file larger than the limit is refused before
/// anything is allocated for it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/result.hpp"

namespace orthoflow::core {

/// @brief Why a file could not be read; message is "<path>: <reason>".
struct FileReadFailure {
  enum class Code : std::uint8_t { OPEN_FAILED, NOT_REGULAR, TOO_LARGE, READ_FAILED };
  Code code = Code::OPEN_FAILED;
  std::string message;
};

/// @brief Reads the whole regular file @p path (at most @p max_bytes) into @p out (replaced).
[[nodiscard]] Result<void, FileReadFailure> read_regular_file(const std::filesystem::path& path,
                                                              std::size_t max_bytes,
                                                              std::vector<char>& out);

/// @brief The same, as text.
[[nodiscard]] Result<std::string, FileReadFailure> read_regular_text(
    const std::filesystem::path& path, std::size_t max_bytes);

}  // namespace orthoflow::core
