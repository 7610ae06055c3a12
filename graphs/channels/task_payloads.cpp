#include "graphs/channels/task_payloads.hpp"

#include <cstring>
#include <type_traits>

#include "core/label_text.hpp"
#include "graphs/channels/payload_decode.hpp"

namespace orthoflow::graphs {

namespace {

using Kind = TaskCommand::Kind;

template <class Payload>
bool read_whole(std::span<const std::byte> bytes, std::uint32_t type_id, Payload& out,
                std::string& error) {
  return read_whole_payload(bytes, type_id, TASK_IPC_VERSION, out, error);
}

constexpr std::uint32_t LAST_TASK =
    static_cast<std::uint32_t>(manipulation::TableTaskKind::SERVE_A_MEAL);

}  // namespace

const char* to_string(TaskCommand::Kind kind) noexcept {
  return kind == Kind::START ? "start" : "stop";
}

const char* to_string(TaskState state) noexcept {
  switch (state) {
    case TaskState::IDLE:
      return "idle";
    case TaskState::RUNNING:
      return "running";
    default:
      return "finished";
  }
}

const char* to_string(TaskAnswer answer) noexcept {
  switch (answer) {
    case TaskAnswer::NONE:
      return "none";
    case TaskAnswer::STARTED:
      return "started";
    case TaskAnswer::STOPPING:
      return "stopping";
    case TaskAnswer::REFUSED:
      return "refused";
    default:
      return "invalid";
  }
}

void reset_header(TaskCommandPayload& p) noexcept {
  reset_payload_header(p, TASK_COMMAND_TYPE_ID, TASK_IPC_VERSION);
}

void reset_header(TaskStatusPayload& p) noexcept {
  reset_payload_header(p, TASK_STATUS_TYPE_ID, TASK_IPC_VERSION);
}

bool encode_task_command(const TaskCommand& command, std::uint64_t client, std::uint64_t request,
                         TaskCommandPayload& out) noexcept {
  if (command.bring.size() > TASK_MAX_BRING) return false;
  for (const std::string& b : command.bring)
    if (core::check_label(b) != core::LabelProblem::NONE) return false;
  reset_header(out);
  out.kind = static_cast<std::uint32_t>(command.kind);
  out.task = static_cast<std::uint32_t>(command.task);
  out.client = client;
  out.request = request;
  out.bring_count = static_cast<std::uint32_t>(command.bring.size());
  for (std::size_t i = 0; i < command.bring.size(); ++i) out.bring[i].assign(command.bring[i]);
  return true;
}

Result<RemoteTaskCommand, TaskCommandProblem> decode_task_command(
    std::span<const std::byte> bytes) {
  TaskCommandPayload p;
  TaskCommandProblem problem;
  if (!read_whole(bytes, TASK_COMMAND_TYPE_ID, p, problem.message)) return err(std::move(problem));
  problem.client = p.client;
  problem.request = p.request;
  if (p.kind > static_cast<std::uint32_t>(Kind::STOP)) {
    problem.message = "unknown command kind " + std::to_string(p.kind);
    return err(std::move(problem));
  }
  if (p.task > LAST_TASK) {
    problem.message = "unknown task " + std::to_string(p.task);
    return err(std::move(problem));
  }
  if (p.bring_count > TASK_MAX_BRING) {
    problem.message =
        "bring_count " + std::to_string(p.bring_count) + " above " + std::to_string(TASK_MAX_BRING);
    return err(std::move(problem));
  }
  RemoteTaskCommand out;
  out.client = p.client;
  out.request = p.request;
  out.command.kind = static_cast<Kind>(p.kind);
  out.command.task = static_cast<manipulation::TableTaskKind>(p.task);
  for (std::uint32_t i = 0; i < p.bring_count; ++i) {
    const std::size_t n = ::strnlen(p.bring[i].chars.data(), p.bring[i].chars.size());
    const std::string_view label(p.bring[i].chars.data(), n);
    const core::LabelProblem check =
        n == p.bring[i].chars.size() ? core::LabelProblem::TOO_LONG : core::check_label(label);
    if (check != core::LabelProblem::NONE) {
      problem.message =
          "category " + std::to_string(i) + ": " + std::string(core::to_string(check));
      return err(std::move(problem));
    }
    out.command.bring.emplace_back(label);
  }
  if (out.command.kind == Kind::START &&
      out.command.task == manipulation::TableTaskKind::SERVE_A_MEAL && out.command.bring.empty()) {
    problem.message = "serve_a_meal names no category to bring";
    return err(std::move(problem));
  }
  return out;
}

void encode_task_status(const TaskStatus& status, TaskStatusPayload& out) noexcept {
  reset_header(out);
  out.state = static_cast<std::uint32_t>(status.state);
  out.task = static_cast<std::uint32_t>(status.task);
  out.client = status.client;
  out.request = status.request;
  out.answer = static_cast<std::uint32_t>(status.answer);
  out.move = status.move;
  out.moves = status.moves;
  out.done = status.done;
  out.published_ns = status.published_ns;
  out.phase = static_cast<std::uint32_t>(status.phase);
  out.message.assign_elided(status.message);
}

Result<TaskStatus, std::string> decode_task_status(std::span<const std::byte> bytes) {
  TaskStatusPayload p;
  std::string error;
  if (!read_whole(bytes, TASK_STATUS_TYPE_ID, p, error)) return err(std::move(error));
  if (p.state > static_cast<std::uint32_t>(TaskState::FINISHED))
    return err("state " + std::to_string(p.state) + " out of range");
  if (p.task > LAST_TASK) return err("task " + std::to_string(p.task) + " out of range");
  if (p.answer > static_cast<std::uint32_t>(TaskAnswer::INVALID))
    return err("answer " + std::to_string(p.answer) + " out of range");
  if (p.phase >= manipulation::PHASE_COUNT)
    return err("phase " + std::to_string(p.phase) + " out of range");
  if (p.move > p.moves || p.done > p.move)
    return err("move counts out of order (" + std::to_string(p.done) + " done of " +
               std::to_string(p.move) + " tried of " + std::to_string(p.moves) + ")");
  const std::size_t n = ::strnlen(p.message.chars.data(), p.message.chars.size());
  if (n == p.message.chars.size()) return err(std::string("message is not zero-terminated"));
  TaskStatus out;
  out.state = static_cast<TaskState>(p.state);
  out.task = static_cast<manipulation::TableTaskKind>(p.task);
  out.client = p.client;
  out.request = p.request;
  out.answer = static_cast<TaskAnswer>(p.answer);
  out.move = p.move;
  out.moves = p.moves;
  out.done = p.done;
  out.published_ns = p.published_ns;
  out.phase = static_cast<manipulation::Phase>(p.phase);
  out.message.assign(p.message.chars.data(), n);
  return out;
}

std::string task_commands_topic(const std::string& graph) {
  return "orthoflow/" + graph + "/task_commands";
}
std::string task_status_topic(const std::string& graph) {
  return "orthoflow/" + graph + "/task_status";
}

}  // namespace orthoflow::graphs
