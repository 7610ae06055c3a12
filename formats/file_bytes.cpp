#include "formats/file_bytes.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

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
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return err(IoError{IoError::Code::OPEN_FAILED, path.string() + ": is a directory"});
  }
  File file(std::fopen(path.c_str(), "rb"));
  if (!file) { return err(io_error(IoError::Code::OPEN_FAILED, path, "cannot open")); }
  std::vector<char> bytes;
  char chunk[1 << 16];
  std::size_t got = 0;
  while ((got = std::fread(chunk, 1, sizeof(chunk), file.get())) > 0) {
    if (bytes.size() + got > max_bytes) {
      return err(IoError{IoError::Code::TOO_LARGE,
                         path.string() + ": larger than the input limit of " +
                             std::to_string(max_bytes) + " bytes (ORTHOFLOW_MAX_INPUT_BYTES)"});
    }
    bytes.insert(bytes.end(), chunk, chunk + got);
  }
  if (std::ferror(file.get()) != 0) {
    return err(io_error(IoError::Code::OPEN_FAILED, path, "read failed"));
  }
  return bytes;
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
