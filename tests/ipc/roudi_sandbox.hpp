#pragma once
/// @file
/// @brief Test support: runs an IPC scenario in a forked child with a private mount namespace and
/// fresh tmpfs on /dev/shm and /tmp, so that every test has its own RouDi (iceoryx 2.0.3 allows one
/// per machine: fixed shm, socket and lock names). Every wait is bounded; a hung process is killed.
#include <sys/types.h>

#include <chrono>
#include <functional>
#include <string>
#include <vector>

namespace orthoflow::tests {

/// @brief How a spawned process ended.
struct ProcResult {
  int exit_code = -1;    ///< exit status, -1 if signalled or hung
  int signal = 0;        ///< terminating signal, 0 if it exited
  bool hung = false;     ///< still running at the deadline (then SIGKILLed)
  double seconds = 0;    ///< from spawn to exit
  std::string out, err;  ///< its stdout and stderr
};

/// @brief Helpers available inside the isolated child. Not thread-safe.
class Sandbox {
 public:
  /// @brief Starts `orthoflow ARGS...` with stdout/stderr in /tmp/NAME.{out,err}.
  pid_t spawn_orthoflow(const std::string& name, const std::vector<std::string>& args);
  /// @brief Starts the program @p argv[0] (a path) with its arguments, output as spawn_orthoflow.
  pid_t spawn_program(const std::string& name, const std::vector<std::string>& argv);
  /// @brief Starts `iox-roudi -c CONFIG` (default config/roudi_test.toml; setsid, stdin /dev/null)
  /// and waits at most 5 s until engine::probe_roudi succeeds. Records a failure and returns -1
  /// otherwise.
  pid_t start_roudi(const std::string& config = ORTHOFLOW_SOURCE_DIR "/config/roudi_test.toml");
  /// @brief Waits at most `timeout` for `pid` (kills it if hung) and collects its output.
  ProcResult wait(pid_t pid, std::chrono::milliseconds timeout);
  /// @brief Waits at most `timeout` until NAME's stdout contains `needle`.
  bool wait_for_output(pid_t pid, const std::string& needle, std::chrono::milliseconds timeout);
  /// @brief Records a failure unless `ok`.
  void check(bool ok, const std::string& what);
  /// @brief Records a failure with a process's output unless `ok`.
  void check(bool ok, const std::string& what, const ProcResult& proc);
  [[nodiscard]] const std::string& failures() const noexcept { return failures_; }
  /// @brief SIGKILLs every process still running (RouDi included) and reaps it.
  void kill_all();

 private:
  struct Child {
    pid_t pid;
    std::string name;
    std::chrono::steady_clock::time_point start;
    bool reaped;
  };
  pid_t spawn(const std::string& name, const std::vector<std::string>& argv, bool new_session);
  Child* find(pid_t pid);
  std::vector<Child> children_;
  std::string failures_;
};

/// @brief What happened to an isolated scenario.
struct Outcome {
  bool skipped = false;
  std::string reason;    ///< why it was skipped (no privileges for unshare/mount)
  std::string failures;  ///< empty on success
};

/// @brief Forks a child that enters a private mount namespace with fresh tmpfs on /dev/shm and
/// /tmp and runs `scenario`; waits at most `timeout` (then kills it and reports a failure).
Outcome run_isolated(const std::function<void(Sandbox&)>& scenario, std::chrono::seconds timeout);

/// @brief Lines of `text` that contain `needle`.
std::vector<std::string> lines_with(const std::string& text, const std::string& needle);

}  // namespace orthoflow::tests
