#include "formats/file_bytes.hpp"

#include <cstdlib>
#include <string>

#include "core/file_output.hpp"
#include "core/input_limit.hpp"
#include "core/regular_file.hpp"

namespace orthoflow::formats {

Result<std::vector<char>, IoError> read_file_bytes(const std::filesystem::path& path,
                                                   std::size_t max_bytes) {
  std::vector<char> bytes;
  auto read = core::read_regular_file(path, max_bytes, bytes);
  if (!read) {
    using C = core::FileReadFailure::Code;
    const auto code =
        read.error().code == C::TOO_LARGE ? IoError::Code::TOO_LARGE : IoError::Code::OPEN_FAILED;
    // The general input limit can be raised; a reader's own (a depth image, an index) cannot.
    const bool general = code == IoError::Code::TOO_LARGE && max_bytes == core::max_input_bytes();
    return err(IoError{
        code, read.error().message + (general ? " (ORTHOFLOW_MAX_INPUT_BYTES)" : std::string())});
  }
  return bytes;
}

std::string read_failure_reason(const IoError& error, const std::filesystem::path& path) {
  const std::string prefix = path.string() + ": ";
  return error.message.rfind(prefix, 0) == 0 ? error.message.substr(prefix.size()) : error.message;
}

Result<void, IoError> write_file_atomically(const std::filesystem::path& path,
                                            std::string_view bytes) {
  auto written = core::write_whole_file(path, bytes);
  if (!written) return err(IoError{IoError::Code::WRITE_FAILED, std::move(written.error())});
  return {};
}

}  // namespace orthoflow::formats
