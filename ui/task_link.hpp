#pragma once
/// @file
/// @brief The web view's control of the table tasks (docs/MANIPULATION.md section 6): a link to the
/// process that runs them (`orthoflow task run`), through which the page starts and stops a task
/// and reads its state. IpcTaskLink (ui/ipc_task_link.hpp) is the link over iceoryx's task
/// command channel; the server works with any TaskLink.
#include <cstdint>
#include <optional>
#include <string>

#include "graphs/channels/task_payloads.hpp"
#include "ui/ui_backend.hpp"

namespace orthoflow::ui {

/// @brief The newest state the task process published, and how old it is.
struct TaskView {
  graphs::TaskStatus status;
  std::int64_t age_ms = 0;
};

/// @brief What became of a command sent to the task process.
struct TaskReply {
  enum class Status : std::uint8_t {
    ANSWERED,         ///< status holds the task process's answer to this command
    NO_TASK_PROCESS,  ///< nobody takes task commands: nothing was sent
    TIMEOUT,          ///< sent, but no answer within the timeout
    INVALID,          ///< the command cannot be sent (a category that is not a label)
  };
  Status status = Status::TIMEOUT;
  graphs::TaskStatus answer;
};

/// @brief What became of the web view's stop button (graphs/services/arm_stop_service.hpp).
struct ArmStopReply {
  enum class Status : std::uint8_t {
    STOPPED,    ///< the process holding the arm halted and latched it
    NO_HOLDER,  ///< nobody holding an arm listens: nothing was sent
    TIMEOUT,    ///< sent, no answer within the timeout
  };
  Status status = Status::TIMEOUT;
  bool was_moving = false;
  int holder_pid = 0;
  std::string holder;
  double request_to_halt_ms = 0.0;
};

/// @note Implementations are thread-safe.
class TaskLink {
 public:
  virtual ~TaskLink() = default;
  /// @brief The newest status the task process published, or nullopt when none arrived within
  /// the last 2 s (no task process, or it stopped).
  [[nodiscard]] virtual std::optional<TaskView> view() const = 0;
  /// @brief Sends @p command and waits at most @p timeout_ms for its answer.
  [[nodiscard]] virtual TaskReply send(const graphs::TaskCommand& command, int timeout_ms) = 0;
  /// @brief Asks whatever process holds the arm to halt it in place and latch (no task needed).
  [[nodiscard]] virtual ArmStopReply stop_arm(int timeout_ms) = 0;
};

/// @brief @p backend's snapshot with the task's state from its task link (none without one).
[[nodiscard]] inline UiSnapshot snapshot_with_task(const UiBackend& backend) {
  const TaskLink* link = backend.task_link();
  UiSnapshot s = backend.snapshot();
  s.task_control = link != nullptr;
  if (link != nullptr) {
    if (auto v = link->view()) {
      s.task = v->status;
      s.task_age_ms = v->age_ms;
    }
  }
  return s;
}

}  // namespace orthoflow::ui
