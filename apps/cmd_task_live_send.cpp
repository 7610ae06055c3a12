// `orthoflow task start|stop|status`: one command to a running `orthoflow task run` on
// orthoflow/<graph>/task_commands, and its answer from orthoflow/<graph>/task_status (or, for
// status, the newest status). The options are in cmd_task_live.cpp.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <random>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "apps/task_live_cli.hpp"
#include "engine/ipc_pubsub.hpp"
#include "graphs/channels/task_payloads.hpp"
#include "ui/ui_json.hpp"

namespace orthoflow::apps::task_live_cli {

// One command to a running `task run`, and its answer.
void send_command(const LiveArgs& a, const std::optional<graphs::TaskCommand>& command) {
  init_ipc("orthoflow_task_cli");
  auto status_in = subscriber(graphs::task_status_topic(a.graph),
                              {graphs::TASK_STATUS_TYPE_ID, graphs::TASK_IPC_VERSION},
                              engine::IpcPolicy::QUEUE, 64, 1);
  std::unique_ptr<engine::IpcPublisher> out;
  std::uint64_t client = 0;
  const std::uint64_t request = 1;
  if (command) {
    out = publisher(graphs::task_commands_topic(a.graph),
                    {graphs::TASK_COMMAND_TYPE_ID, graphs::TASK_IPC_VERSION},
                    sizeof(graphs::TaskCommandPayload), 0);
    std::random_device device;
    client = ((static_cast<std::uint64_t>(device()) << 32U) ^ device()) | 1U;
  }
  const auto deadline = Clock::now() + std::chrono::duration<double>(a.timeout_s);
  // Wait for the task process to subscribe (it may have just started), then send once.
  bool sent = !command;
  while (!sent && Clock::now() < deadline) {
    if (out->has_subscribers()) {
      graphs::TaskCommandPayload p;
      if (!graphs::encode_task_command(*command, client, request, p))
        fail("a category is not a valid label", EXIT_USAGE);
      publish_pod(*out, p);
      sent = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!sent) fail("no `orthoflow task run` for graph " + a.graph + " answered", EXIT_UNREACHABLE);
  while (Clock::now() < deadline) {
    auto s = status_in->take();
    if (s && s->has_value()) {
      auto st = graphs::decode_task_status((*s)->bytes());
      if (st && (!command || (st->client == client && st->request == request))) {
        const nlohmann::json j = ui::task_status_json(*st);
        if (a.json)
          std::cout << j.dump() << '\n';
        else
          std::printf("%s: %s%s%s (move %u of %u, %u done)\n", graphs::to_string(st->answer),
                      graphs::to_string(st->state), st->message.empty() ? "" : ": ",
                      st->message.c_str(), st->move, st->moves, st->done);
        if (command && (st->answer == graphs::TaskAnswer::REFUSED ||
                        st->answer == graphs::TaskAnswer::INVALID))
          throw CLI::RuntimeError(EXIT_REFUSED);
        return;
      }
      continue;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  fail("no answer from `orthoflow task run` within " + std::to_string(a.timeout_s) + " s",
       EXIT_UNREACHABLE);
}

}  // namespace orthoflow::apps::task_live_cli
