#pragma once
/// @file
/// @brief (internal) What the parts of `orthoflow task run|start|stop|status` share
/// (cmd_task_live.cpp: the options; cmd_task_live_ipc.cpp: the iceoryx plumbing;
/// cmd_task_live_run.cpp: `task run`, the task on the arm; cmd_task_live_send.cpp: `task start`,
/// `stop` and `status`, one command and its answer): the options, the error exit and the topics.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/arm_cli.hpp"
#include "apps/commands.hpp"
#include "engine/ipc_pubsub.hpp"
#include "graphs/channels/task_payloads.hpp"

namespace orthoflow::apps::task_live_cli {

using Clock = std::chrono::steady_clock;

/// @brief Prints "orthoflow task: WHAT" on stderr and exits with @p code (throws
/// CLI::RuntimeError). @pre none.
[[noreturn]] void fail(const std::string& what, int code = EXIT_FAILURE_GENERIC);

/// @brief The options of `task run|start|stop|status` (add_live_task_commands documents them).
struct LiveArgs {
  std::shared_ptr<arm_cli::ArmArgs> arm = std::make_shared<arm_cli::ArmArgs>();
  std::string graph = "tabletop";
  std::string frames;
  std::string start;               // run --start TASK; start TASK
  std::vector<std::string> bring;  // serve_a_meal's categories
  std::vector<double> area{0.20, -0.50, 0.56, -0.15};
  std::vector<std::string> keep{"plate"};
  std::vector<double> user_place{-0.35, -0.50};
  double seconds = 0.0;              // run: 0 = until a signal
  double timeout_s = 5.0;            // start / stop / status: wait this long for the answer
  double perception_age_ms = 300.0;  // the stale-perception interlock
  bool exit_when_done = false;
  bool json = false;
};

/// @brief The topic named @p name. @pre none (a bad name fails with EXIT_USAGE).
[[nodiscard]] engine::IpcTopic topic_of(const std::string& name);
/// @brief Registers this process with RouDi as WHO_PID. @pre none (no RouDi: EXIT_NO_ROUDI).
void init_ipc(const std::string& who);
/// @brief A publisher of @p bytes-sized samples of @p type on @p topic, keeping @p history.
/// @pre init_ipc() (no fitting pool: EXIT_POOLS).
[[nodiscard]] std::unique_ptr<engine::IpcPublisher> publisher(const std::string& topic,
                                                              engine::IpcPayloadType type,
                                                              std::size_t bytes,
                                                              std::uint64_t history);
/// @brief A subscriber to @p topic of @p type, @p policy, @p depth samples, @p history replayed.
/// @pre init_ipc().
[[nodiscard]] std::unique_ptr<engine::IpcSubscriber> subscriber(const std::string& topic,
                                                                engine::IpcPayloadType type,
                                                                engine::IpcPolicy policy,
                                                                std::uint64_t depth,
                                                                std::uint64_t history);

/// @brief Publishes a copy of the plain payload @p p (a failure is counted by the publisher).
/// @pre Payload is trivially copyable.
template <class Payload>
void publish_pod(engine::IpcPublisher& out, const Payload& p) {
  (void)out.publish_copy({reinterpret_cast<const std::byte*>(&p), sizeof p});
}

/// @brief The start command of --start / `task start` (its task and --bring).
/// @pre none (an unknown task or a bad --bring fails with EXIT_USAGE).
[[nodiscard]] graphs::TaskCommand start_command(const LiveArgs& a);
/// @brief `task run`: the arm, the graph's objects and the task commands until a signal, the time
/// limit or (--exit-when-done) the task's end; then the report. @pre none.
void run_live(const LiveArgs& a);
/// @brief One command to a running `task run` (none: `task status`), and its answer.
/// @pre none (no answer within --timeout: EXIT_UNREACHABLE; refused: EXIT_REFUSED).
void send_command(const LiveArgs& a, const std::optional<graphs::TaskCommand>& command);

}  // namespace orthoflow::apps::task_live_cli
