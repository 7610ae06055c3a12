#include "core/regular_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace orthoflow::core {

namespace {

using Code = FileReadFailure::Code;

FileReadFailure failure(Code code, const std::filesystem::path& path, const std::string& why) {
  return FileReadFailure{code, path.string() + ": " + why};
}

/// Closes the descriptor on every path out.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

std::string too_large(std::size_t max_bytes) {
  return "larger than the limit of " + std::to_string(max_bytes) + " bytes";
}

}  // namespace

Result<void, FileReadFailure> read_regular_file(const std::filesystem::path& path,
                                                std::size_t max_bytes, std::vector<char>& out) {
  out.clear();
  // O_NONBLOCK: opening a FIFO with no writer returns at once instead of waiting for one.
  Descriptor file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (file.fd < 0)
    return err(
        failure(Code::OPEN_FAILED, path, std::string("cannot open: ") + std::strerror(errno)));
  struct stat st {};
  if (::fstat(file.fd, &st) != 0)
    return err(
        failure(Code::OPEN_FAILED, path, std::string("cannot stat: ") + std::strerror(errno)));
  if (S_ISDIR(st.st_mode)) return err(failure(Code::NOT_REGULAR, path, "is a directory"));
  if (!S_ISREG(st.st_mode))
    return err(
        failure(Code::NOT_REGULAR, path, "is not a regular file (a FIFO, socket or device)"));
  if (st.st_size < 0 || static_cast<std::uintmax_t>(st.st_size) > max_bytes)
    return err(failure(Code::TOO_LARGE, path, too_large(max_bytes)));
  out.resize(static_cast<std::size_t>(st.st_size));
  std::size_t have = 0;
  while (true) {  // to the end, which differs from st_size if the file grows while it is read
    if (have == out.size()) {  // the size stat gave is read: one byte more, or the end
      char probe = 0;
      const ssize_t more = ::read(file.fd, &probe, 1);
      if (more == 0) break;
      if (more < 0) {
        if (errno == EINTR) continue;
        return err(
            failure(Code::READ_FAILED, path, std::string("read failed: ") + std::strerror(errno)));
      }
      if (out.size() >= max_bytes) return err(failure(Code::TOO_LARGE, path, too_large(max_bytes)));
      out.resize(std::min(max_bytes, std::max<std::size_t>(2 * out.size(), 4096)));
      out[have++] = probe;
      continue;
    }
    const ssize_t got = ::read(file.fd, out.data() + have, out.size() - have);
    if (got == 0) break;
    if (got < 0) {
      if (errno == EINTR) continue;
      return err(
          failure(Code::READ_FAILED, path, std::string("read failed: ") + std::strerror(errno)));
    }
    have += static_cast<std::size_t>(got);
  }
  out.resize(have);
  return {};
}

Result<std::string, FileReadFailure> read_regular_text(const std::filesystem::path& path,
                                                       std::size_t max_bytes) {
  std::vector<char> bytes;
  if (auto ok = read_regular_file(path, max_bytes, bytes); !ok) return err(ok.error());
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace orthoflow::core
