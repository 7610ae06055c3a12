#include "core/file_output.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace orthoflow::core {
namespace {

std::string failure(const std::filesystem::path& path, const char* what) {
  return path.string() + ": " + what + ": " + std::strerror(errno);
}

/// Writes all of @p bytes to @p fd, retrying short writes and EINTR; false with errno set.
bool write_all(int fd, std::string_view bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      if (w == 0) errno = EIO;
      return false;
    }
    done += static_cast<std::size_t>(w);
  }
  return true;
}

/// A path that exists and is not a regular file: write into it as it is (no O_CREAT, no rename).
Result<void, std::string> write_in_place(const std::filesystem::path& path,
                                         std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return err(failure(path, "cannot open"));
  const bool written = write_all(fd, bytes);
  const int saved = errno;
  if (::close(fd) != 0 && written) return err(failure(path, "cannot close"));
  errno = saved;
  if (!written) return err(failure(path, "cannot write"));
  return {};
}

}  // namespace

Result<void, std::string> write_whole_file(const std::filesystem::path& path,
                                           std::string_view bytes, bool synced) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    if (S_ISDIR(st.st_mode)) {
      errno = EISDIR;
      return err(failure(path, "cannot write"));
    }
    return write_in_place(path, bytes);
  }
  std::filesystem::path tmp = path;
  tmp += ".tmp" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return err(failure(path, ("cannot create " + tmp.string()).c_str()));
  const bool written = write_all(fd, bytes) && (!synced || ::fsync(fd) == 0);
  const int write_errno = errno;
  const bool closed = ::close(fd) == 0;
  if (!written || !closed) {
    if (!written) errno = write_errno;
    auto e = failure(path, ((written ? "cannot close " : "cannot write ") + tmp.string()).c_str());
    ::unlink(tmp.c_str());
    return err(std::move(e));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    auto e = failure(path, "cannot rename into place");
    ::unlink(tmp.c_str());
    return err(std::move(e));
  }
  return {};
}

}  // namespace orthoflow::core
