// The arm's state directory: the holder's lock and the latched stop (arm_state_dir.hpp).
#include "drivers/jaco/arm_state_dir.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>

namespace orthoflow::drivers::jaco {
namespace {

std::string sys_error(const std::string& what) { return what + ": " + std::strerror(errno); }

// The first bytes of a small file (the holder and the latch files are a line or two).
std::string read_small(const std::string& file) {
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text.substr(0, 4096);
}

// "key value" lines.
std::string field(const std::string& text, const std::string& key) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line))
    if (line.rfind(key + " ", 0) == 0) return line.substr(key.size() + 1);
  return {};
}

long to_long(const std::string& text) { return std::strtol(text.c_str(), nullptr, 10); }

}  // namespace

ArmHold& ArmHold::operator=(ArmHold&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    other.fd_ = -1;
  }
  return *this;
}

ArmHold::~ArmHold() {
  if (fd_ >= 0) ::close(fd_);  // closing the descriptor releases the lock
}

Result<ArmStateDir, std::string> ArmStateDir::open(std::string path) {
  if (path.empty()) return err(std::string("the arm's state directory has no path"));
  std::string partial;
  for (std::size_t at = 0; at != std::string::npos;) {
    at = path.find('/', at + 1);
    partial = path.substr(0, at);
    if (::mkdir(partial.c_str(), 0700) != 0 && errno != EEXIST)
      return err(sys_error("cannot create the arm's state directory " + partial));
  }
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0 || !S_ISDIR(info.st_mode))
    return err("the arm's state directory " + path + " is not a directory");
  return ArmStateDir(std::move(path));
}

std::string ArmStateDir::default_path(bool simulated) {
  if (const char* env = std::getenv("ORTHOFLOW_ARM_STATE_DIR"); env != nullptr && *env != '\0')
    return simulated ? std::string(env) + "/sim" : std::string(env);
  if (simulated) return "/tmp/orthoflow-sim-arm-" + std::to_string(::getuid());
  // The package's place (created by the .deb for the robot's service user); a user the package
  // did not set up keeps the arm's state in their own state directory instead.
  const char* system = "/var/lib/orthoflow/arm";
  if (::access(system, W_OK) == 0 || ::access("/var/lib/orthoflow", W_OK) == 0 || ::getuid() == 0)
    return system;
  const char* home = std::getenv("HOME");
  if (home == nullptr || *home == '\0') return system;
  return std::string(home) + "/.local/state/orthoflow/arm";
}

Result<ArmHold, std::string> ArmStateDir::hold(std::string_view what) const {
  const std::string file = path_ + "/holder";
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) return err(sys_error("cannot open " + file));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    const std::optional<ArmHolder> other = holder();
    return err(other ? "the arm is held by pid " + std::to_string(other->pid) + " (" + other->what +
                           ")"
                     : std::string("the arm is held by another process"));
  }
  const std::string text =
      "pid " + std::to_string(::getpid()) + "\nwhat " + std::string(what) + "\n";
  if (::ftruncate(fd, 0) != 0 || ::write(fd, text.data(), text.size()) < 0) {
    ::close(fd);
    return err(sys_error("cannot write " + file));
  }
  return ArmHold(fd);
}

std::optional<ArmHolder> ArmStateDir::holder() const {
  const std::string file = path_ + "/holder";
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  // A shared lock that can be taken means nobody holds the exclusive one.
  const bool free = ::flock(fd, LOCK_SH | LOCK_NB) == 0;
  ::close(fd);
  if (free) return std::nullopt;
  const std::string text = read_small(file);
  return ArmHolder{to_long(field(text, "pid")), field(text, "what")};
}

Result<void, std::string> ArmStateDir::latch(std::string_view reason, bool was_moving) const {
  const std::string file = path_ + "/estop";
  const std::string temporary = file + ".tmp" + std::to_string(::getpid());
  std::string text = "reason ";
  for (const char c : reason) text += (c == '\n' ? ' ' : c);
  text += "\npid " + std::to_string(::getpid()) + "\nunix_s " +
          std::to_string(static_cast<long long>(std::time(nullptr))) + "\nwas_moving " +
          (was_moving ? "1" : "0") + "\n";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return err(sys_error("cannot write " + temporary));
  const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (!written || !synced || ::rename(temporary.c_str(), file.c_str()) != 0) {
    ::unlink(temporary.c_str());
    return err(sys_error("cannot latch the stop in " + file));
  }
  return {};
}

std::optional<ArmLatch> ArmStateDir::latched() const {
  const std::string file = path_ + "/estop";
  if (::access(file.c_str(), F_OK) != 0) return std::nullopt;
  const std::string text = read_small(file);
  ArmLatch latch;
  latch.reason = field(text, "reason");
  if (latch.reason.empty()) latch.reason = "(unreadable latch file: treated as latched)";
  latch.pid = to_long(field(text, "pid"));
  latch.unix_s = to_long(field(text, "unix_s"));
  latch.was_moving = field(text, "was_moving") == "1";
  return latch;
}

Result<void, std::string> ArmStateDir::clear_latch() const {
  const std::string file = path_ + "/estop";
  if (::unlink(file.c_str()) != 0 && errno != ENOENT)
    return err(sys_error("cannot remove " + file));
  return {};
}

}  // namespace orthoflow::drivers::jaco
