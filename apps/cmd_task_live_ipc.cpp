// `orthoflow task run|start|stop|status`, the iceoryx plumbing both sides use: topics, the
// registration with RouDi, publishers and subscribers, each failure an exit code (docs/IPC.md).
#include <unistd.h>

#include <chrono>
#include <string>

#include "apps/task_live_cli.hpp"
#include "engine/ipc_pubsub.hpp"
#include "engine/ipc_runtime.hpp"

namespace orthoflow::apps::task_live_cli {

engine::IpcTopic topic_of(const std::string& name) {
  auto t = engine::parse_topic(name);
  if (!t) fail("bad topic " + name + ": " + engine::to_string(t.error()), EXIT_USAGE);
  return *t;
}

void init_ipc(const std::string& who) {
  if (auto init = engine::init_ipc_runtime(who + "_" + std::to_string(::getpid())); !init)
    fail(to_string(init.error()), EXIT_NO_ROUDI);
}

std::unique_ptr<engine::IpcPublisher> publisher(const std::string& topic,
                                                engine::IpcPayloadType type, std::size_t bytes,
                                                std::uint64_t history) {
  auto pools = engine::query_roudi_pools(std::chrono::milliseconds(3000));
  if (!pools) fail(to_string(pools.error()), EXIT_NO_ROUDI);
  auto p = engine::IpcPublisher::create(topic_of(topic), {type, bytes, history, false}, *pools);
  if (!p)
    fail(to_string(p.error()), p.error().code == engine::IpcError::Code::NO_FITTING_POOL
                                   ? EXIT_POOLS
                                   : EXIT_FAILURE_GENERIC);
  return std::move(*p);
}

std::unique_ptr<engine::IpcSubscriber> subscriber(const std::string& topic,
                                                  engine::IpcPayloadType type,
                                                  engine::IpcPolicy policy, std::uint64_t depth,
                                                  std::uint64_t history) {
  auto s = engine::IpcSubscriber::create(topic_of(topic), {type, policy, depth, history});
  if (!s) fail(to_string(s.error()));
  return std::move(*s);
}

}  // namespace orthoflow::apps::task_live_cli
