#pragma once
/// @file
/// @brief The task command channel across processes (issue 21, item 5): how a CLI, a UI or a
/// bridge starts and stops a table task on a live arm run by `orthoflow task run` (docs/IPC.md,
/// docs/MANIPULATION.md section 5). Beside a graph's learning channel, in its conventions:
/// - `orthoflow/<graph>/task_commands`: TaskCommandPayload, one per action (start a task, stop it);
/// - `orthoflow/<graph>/task_status`: TaskStatusPayload, the task's state a few times a second
///   and at once after every command, carrying the newest command's answer (`client`, `request`),
///   for every sender (each takes the ones with its own `client` id).
/// Fixed-size PODs with the header every payload has (type id, version, payload_bytes at offset
/// 48). Both ends decode with the functions below, which check every field another process could
/// have got wrong (kind, task, counts, category labels by core::check_label).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "manipulation/table_task_runner.hpp"

namespace orthoflow::graphs {

inline constexpr std::uint32_t TASK_COMMAND_TYPE_ID = 0x4354464FU;  ///< "OFTC"
inline constexpr std::uint32_t TASK_STATUS_TYPE_ID = 0x5354464FU;   ///< "OFTS"
inline constexpr std::uint16_t TASK_IPC_VERSION = 1;
/// @brief Categories a start of serve_a_meal names at most.
inline constexpr std::uint32_t TASK_MAX_BRING = 4;

/// @brief What a sender asks of the task process.
struct TaskCommand {
  enum class Kind : std::uint8_t {
    START,  ///< plan the task on the newest objects and run it (refused while one runs)
    STOP,   ///< stop the task: the running job backs away (or holds), no further move starts
  };
  Kind kind = Kind::START;
  manipulation::TableTaskKind task = manipulation::TableTaskKind::CLEAR_TABLE;
  std::vector<std::string> bring;  ///< START of serve_a_meal: the categories, in order
};

/// @brief "start" or "stop".
[[nodiscard]] const char* to_string(TaskCommand::Kind kind) noexcept;

struct alignas(64) TaskCommandPayload {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint32_t kind;  ///< TaskCommand::Kind
  std::uint32_t task;  ///< manipulation::TableTaskKind
  std::uint64_t client;
  std::uint64_t request;
  std::uint32_t bring_count;
  std::uint32_t reserved1;
  std::uint64_t reserved2;
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(TaskCommandPayload)
  std::uint64_t reserved3;
  core::Text bring[TASK_MAX_BRING];  ///< zero-terminated labels
};
static_assert(offsetof(TaskCommandPayload, payload_bytes) == 48);
static_assert(sizeof(TaskCommandPayload) == 320);

/// @brief The task process's state.
enum class TaskState : std::uint32_t {
  IDLE,      ///< no task started yet: waiting for a start
  RUNNING,   ///< a task runs (planning a move, parking, or a job)
  FINISHED,  ///< the last task ended (message: why it stopped early, if it did)
};
[[nodiscard]] const char* to_string(TaskState state) noexcept;

/// @brief How the task process answered the newest command.
enum class TaskAnswer : std::uint32_t {
  NONE,      ///< no command answered yet
  STARTED,   ///< the task was planned and runs
  STOPPING,  ///< the stop was taken: the running job backs away, then the task ends
  REFUSED,   ///< a start while a task runs, no fresh objects, a category nobody taught, a stop
             ///< with no task running (message: why)
  INVALID,   ///< the command failed validation (kind, task, labels): nothing was done
};
[[nodiscard]] const char* to_string(TaskAnswer answer) noexcept;

struct alignas(64) TaskStatusPayload {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint32_t state;          ///< TaskState
  std::uint32_t task;           ///< manipulation::TableTaskKind of the newest task
  std::uint64_t client;         ///< the newest answered command's sender (0: none)
  std::uint64_t request;        ///< and its number
  std::uint32_t answer;         ///< TaskAnswer
  std::uint32_t move;           ///< moves tried so far
  std::uint32_t moves;          ///< moves planned
  std::uint32_t done;           ///< moves the execution manager finished
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(TaskStatusPayload)
  std::int64_t published_ns;    ///< steady clock of the task's host
  std::uint32_t phase;          ///< manipulation::Phase of the running job
  std::uint32_t reserved1;
  std::uint64_t reserved2[3];
  core::Text message;  ///< the answer's reason (refused, invalid) or why the task stopped
};
static_assert(offsetof(TaskStatusPayload, payload_bytes) == 48);
static_assert(sizeof(TaskStatusPayload) == 192);

/// @brief A command as the task process takes it, with its sender's ids.
struct RemoteTaskCommand {
  std::uint64_t client = 0, request = 0;
  TaskCommand command;
};

/// @brief The status as a sender reads it.
struct TaskStatus {
  TaskState state = TaskState::IDLE;
  manipulation::TableTaskKind task = manipulation::TableTaskKind::CLEAR_TABLE;
  std::uint64_t client = 0, request = 0;
  TaskAnswer answer = TaskAnswer::NONE;
  std::uint32_t move = 0, moves = 0, done = 0;
  std::int64_t published_ns = 0;
  manipulation::Phase phase = manipulation::Phase::IDLE;
  std::string message;
};

/// @brief Writes @p command into @p out. @return false when a category does not pass
/// core::check_label or there are more than TASK_MAX_BRING: nothing to send.
[[nodiscard]] bool encode_task_command(const TaskCommand& command, std::uint64_t client,
                                       std::uint64_t request, TaskCommandPayload& out) noexcept;
/// @brief Why a command payload was refused: the words, and its sender's ids when the payload was
/// whole enough to name them.
struct TaskCommandProblem {
  std::uint64_t client = 0, request = 0;
  std::string message;
};
/// @brief Reads a command another process wrote. Errors: short or wrong header, unknown kind or
/// task, a count above TASK_MAX_BRING, a category not zero-terminated or failing
/// core::check_label, a start of serve_a_meal that names none.
[[nodiscard]] Result<RemoteTaskCommand, TaskCommandProblem> decode_task_command(
    std::span<const std::byte> bytes);

void encode_task_status(const TaskStatus& status, TaskStatusPayload& out) noexcept;
/// @brief Errors: short or wrong header, state, task, answer or phase out of range, a message not
/// zero-terminated.
[[nodiscard]] Result<TaskStatus, std::string> decode_task_status(std::span<const std::byte> bytes);

void reset_header(TaskCommandPayload& p) noexcept;
void reset_header(TaskStatusPayload& p) noexcept;

/// @brief orthoflow/<graph>/task_commands and orthoflow/<graph>/task_status.
[[nodiscard]] std::string task_commands_topic(const std::string& graph);
[[nodiscard]] std::string task_status_topic(const std::string& graph);

}  // namespace orthoflow::graphs
