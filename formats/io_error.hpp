#pragma once
/// @file
/// @brief The error every file reader and writer in formats/ returns.
#include <cstdint>
#include <string>

namespace orthoflow::formats {

/// @brief What went wrong reading or writing a file, and where.
struct IoError {
  enum class Code : std::uint8_t {
    OPEN_FAILED,    ///< the file could not be opened or read
    WRITE_FAILED,   ///< the file could not be written
    BAD_HEADER,     ///< a header line is missing, unknown or malformed
    UNSUPPORTED,    ///< a valid but unsupported feature (type, size, encoding)
    SIZE_MISMATCH,  ///< declared sizes disagree (POINTS vs WIDTH x HEIGHT, compressed sizes, ...)
    TRUNCATED,      ///< the data ends before the header says it should
    CORRUPT_DATA,   ///< the compressed block does not decompress
    BAD_NUMBER,     ///< an ASCII value is not a number of the declared type
    TOO_LARGE,      ///< declared sizes exceed what orthoflow accepts (2^31 points, 1 GiB records)
  };
  Code code = Code::BAD_HEADER;
  std::string message;  ///< what and where: "scene.pcd: line 7: ..." or "scene.pcd: byte 1234: ..."

  /// @brief "<code name>: <message>".
  [[nodiscard]] std::string to_string() const;
};

/// @brief The enumerator's name in lower case, e.g. "truncated".
[[nodiscard]] const char* to_string(IoError::Code code) noexcept;

}  // namespace orthoflow::formats
