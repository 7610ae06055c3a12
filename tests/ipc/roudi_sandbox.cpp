#include "tests/ipc/roudi_sandbox.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "engine/ipc_runtime.hpp"

extern char** environ;

namespace orthoflow::tests {

namespace {

using Clock = std::chrono::steady_clock;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_all(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

// "why" for a failed system call: "SKIP ..." when it lacks privileges, else "FAIL ...".
std::string setup_error(const char* what) {
  const int error = errno;
  return std::string(error == EPERM || error == EACCES ? "SKIP " : "FAIL ") + what + ": " +
         std::strerror(error) + " (needs root or CAP_SYS_ADMIN for a private mount namespace)";
}

// Where the host's /tmp stays reachable after a fresh tmpfs covers /tmp (inside the private
// /dev/shm).
constexpr const char* HOST_TMP = "/dev/shm/.host_tmp";

// mkdir -p (0755); false on the first failure other than EEXIST.
bool make_dirs(const std::string& path) {
  for (std::size_t at = 1; at <= path.size(); ++at) {
    if (at != path.size() && path[at] != '/') continue;
    if (::mkdir(path.substr(0, at).c_str(), 0755) != 0 && errno != EEXIST) return false;
  }
  return true;
}

// A build or checkout under /tmp (CI clones there) would vanish under the fresh tmpfs: bind it back
// from the host's /tmp so the orthoflow binary and config files stay where the test expects them.
bool keep_visible(const std::string& dir) {
  if (dir.rfind("/tmp/", 0) != 0) return true;
  const std::string host = std::string(HOST_TMP) + dir.substr(4);
  return make_dirs(dir) &&
         ::mount(host.c_str(), dir.c_str(), nullptr, MS_BIND | MS_REC, nullptr) == 0;
}

// Returns an empty string on success, else why the namespace could not be set up.
std::string enter_private_mounts() {
  if (::unshare(CLONE_NEWNS) != 0) return setup_error("unshare(CLONE_NEWNS)");
  if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0)
    return setup_error("mount rprivate /");
  if (::mount("tmpfs", "/dev/shm", "tmpfs", 0, "mode=1777") != 0)
    return setup_error("mount tmpfs /dev/shm");
  if (!make_dirs(HOST_TMP) || ::mount("/tmp", HOST_TMP, nullptr, MS_BIND | MS_REC, nullptr) != 0) {
    return setup_error("bind the host /tmp");
  }
  if (::mount("tmpfs", "/tmp", "tmpfs", 0, "mode=1777") != 0)
    return setup_error("mount tmpfs /tmp");
  if (!keep_visible(ORTHOFLOW_SOURCE_DIR) || !keep_visible(ORTHOFLOW_BINARY_DIR)) {
    return setup_error("bind the source and build directories back under /tmp");
  }
  // The arm's holder lock and latched stop (drivers/jaco/arm_state_dir.hpp): fresh for each
  // scenario, as its RouDi is.
  ::setenv("ORTHOFLOW_ARM_STATE_DIR", "/tmp/arm_state", 1);
  return {};
}

}  // namespace

pid_t Sandbox::spawn(const std::string& name, const std::vector<std::string>& argv,
                     bool new_session) {
  const std::string out = "/tmp/" + name + ".out", err = "/tmp/" + name + ".err";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the scenario
    if (new_session) ::setsid();
    const int in_fd = ::open("/dev/null", O_RDONLY);
    const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(in_fd, 0);
    ::dup2(out_fd, 1);
    ::dup2(err_fd, 2);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execve(args[0], args.data(), environ);
    ::_exit(127);
  }
  if (pid < 0) {
    check(false, "fork for " + name + ": " + std::strerror(errno));
    return -1;
  }
  children_.push_back(Child{pid, name, Clock::now(), false});
  return pid;
}

pid_t Sandbox::spawn_orthoflow(const std::string& name, const std::vector<std::string>& args) {
  std::vector<std::string> argv{ORTHOFLOW_BINARY_DIR "/apps/orthoflow"};
  argv.insert(argv.end(), args.begin(), args.end());
  return spawn(name, argv, false);
}

pid_t Sandbox::spawn_program(const std::string& name, const std::vector<std::string>& argv) {
  return spawn(name, argv, false);
}

pid_t Sandbox::start_roudi(const std::string& config) {
  const pid_t pid = spawn("roudi", {"/usr/bin/iox-roudi", "-c", config}, true);
  const auto until = Clock::now() + std::chrono::seconds(5);
  while (Clock::now() < until) {
    if (engine::probe_roudi()) return pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  check(false,
        "RouDi not reachable within 5 s: " + slurp("/tmp/roudi.out") + slurp("/tmp/roudi.err"));
  return -1;
}

Sandbox::Child* Sandbox::find(pid_t pid) {
  for (auto& c : children_) {
    if (c.pid == pid) return &c;
  }
  return nullptr;
}

ProcResult Sandbox::wait(pid_t pid, std::chrono::milliseconds timeout) {
  ProcResult result;
  Child* child = find(pid);
  if (child == nullptr || child->reaped) return result;
  const auto until = Clock::now() + timeout;
  int status = 0;
  pid_t done = 0;
  while ((done = ::waitpid(pid, &status, WNOHANG)) == 0 && Clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (done == 0) {
    result.hung = true;
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
  }
  child->reaped = true;
  result.seconds = std::chrono::duration<double>(Clock::now() - child->start).count();
  if (!result.hung && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  if (!result.hung && WIFSIGNALED(status)) result.signal = WTERMSIG(status);
  result.out = slurp("/tmp/" + child->name + ".out");
  result.err = slurp("/tmp/" + child->name + ".err");
  return result;
}

bool Sandbox::wait_for_output(pid_t pid, const std::string& needle,
                              std::chrono::milliseconds timeout) {
  const Child* child = find(pid);
  if (child == nullptr) return false;
  const auto until = Clock::now() + timeout;
  while (Clock::now() < until) {
    if (slurp("/tmp/" + child->name + ".out").find(needle) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

void Sandbox::check(bool ok, const std::string& what) {
  if (!ok) failures_ += what + "\n";
}

void Sandbox::check(bool ok, const std::string& what, const ProcResult& proc) {
  if (ok) return;
  std::ostringstream text;
  text << what << " [exit " << proc.exit_code << ", signal " << proc.signal
       << (proc.hung ? ", HUNG" : "") << ", " << proc.seconds << " s]\n--- stdout:\n"
       << proc.out.substr(0, 3000) << "--- stderr:\n"
       << proc.err.substr(0, 3000);
  failures_ += text.str() + "\n";
}

void Sandbox::kill_all() {
  for (auto& c : children_) {
    if (c.reaped) continue;
    ::kill(c.pid, SIGKILL);
    ::waitpid(c.pid, nullptr, 0);
    c.reaped = true;
  }
}

Outcome run_isolated(const std::function<void(Sandbox&)>& scenario, std::chrono::seconds timeout) {
  int fds[2];
  if (::pipe(fds) != 0) return Outcome{false, {}, "pipe failed"};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    if (auto why = enter_private_mounts(); !why.empty()) {
      write_all(fds[1], why);
      ::_exit(0);
    }
    Sandbox sandbox;
    scenario(sandbox);
    sandbox.kill_all();
    write_all(fds[1], "DONE " + sandbox.failures());
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string text;
  const auto until = Clock::now() + timeout;
  bool hung = true;
  while (Clock::now() < until) {
    pollfd p{fds[0], POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    char buffer[4096];
    const ssize_t n = ::read(fds[0], buffer, sizeof(buffer));
    if (n <= 0) {
      hung = false;
      break;
    }
    text.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (hung) ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
  if (hung)
    return Outcome{
        false, {}, "scenario hung for " + std::to_string(timeout.count()) + " s: " + text};
  if (text.rfind("SKIP ", 0) == 0) return Outcome{true, text.substr(5), {}};
  if (text.rfind("DONE ", 0) == 0) return Outcome{false, {}, text.substr(5)};
  return Outcome{false, {}, text.empty() ? "scenario child died without a report" : text};
}

std::vector<std::string> lines_with(const std::string& text, const std::string& needle) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.find(needle) != std::string::npos) lines.push_back(line);
  }
  return lines;
}

}  // namespace orthoflow::tests
