#include "formats/file_bytes.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "core/input_limit.hpp"
#include "core/regular_file.hpp"

namespace orthoflow::formats {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

IoError io_error(IoError::Code code, const std::filesystem::path& path, const char* what) {
  return IoError{code, path.string() + ": " + what + ": " + std::strerror(errno)};
}

}  // namespace

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
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    File file(std::fopen(tmp.c_str(), "wb"));
    if (!file) { return err(io_error(IoError::Code::WRITE_FAILED, tmp, "cannot create")); }
    if (std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size() ||
        std::fflush(file.get()) != 0) {
      auto e = io_error(IoError::Code::WRITE_FAILED, tmp, "write failed");
      std::remove(tmp.c_str());
      return err(e);
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    auto e = io_error(IoError::Code::WRITE_FAILED, path, "rename failed");
    std::remove(tmp.c_str());
    return err(e);
  }
  return {};
}

}  // namespace orthoflow::formats
