#include "formats/io_error.hpp"

namespace orthoflow::formats {

const char* to_string(IoError::Code code) noexcept {
  switch (code) {
    case IoError::Code::OPEN_FAILED:
      return "open_failed";
    case IoError::Code::WRITE_FAILED:
      return "write_failed";
    case IoError::Code::BAD_HEADER:
      return "bad_header";
    case IoError::Code::UNSUPPORTED:
      return "unsupported";
    case IoError::Code::SIZE_MISMATCH:
      return "size_mismatch";
    case IoError::Code::TRUNCATED:
      return "truncated";
    case IoError::Code::CORRUPT_DATA:
      return "corrupt_data";
    case IoError::Code::BAD_NUMBER:
      return "bad_number";
    case IoError::Code::TOO_LARGE:
      return "too_large";
  }
  return "unknown";
}

std::string IoError::to_string() const {
  return std::string(formats::to_string(code)) + ": " + message;
}

}  // namespace orthoflow::formats
