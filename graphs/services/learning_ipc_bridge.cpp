#include "graphs/services/learning_ipc_bridge.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <utility>
#include <vector>

#include "engine/ipc_pubsub.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/channels/learning_payloads.hpp"

namespace orthoflow::graphs {

namespace {

using Clock = std::chrono::steady_clock;
constexpr auto ANSWER_TIMEOUT = std::chrono::seconds(5);
constexpr auto STATUS_PERIOD = std::chrono::milliseconds(200);
constexpr std::size_t MAX_PENDING = 64;

template <class Payload>
void publish(engine::IpcPublisher& publisher, const Payload& payload) noexcept {
  (void)publisher.publish_copy(
      std::span<const std::byte>(reinterpret_cast<const std::byte*>(&payload), sizeof payload));
}

void fill_status(const LearningService& learning, const engine::GraphStats& stats,
                 StatusPayload& p) {
  reset_header(p);
  p.durable = learning.durable() ? 1U : 0U;
  const auto categories = learning.learner().categories();
  p.categories_total = static_cast<std::uint32_t>(categories.size());
  for (const learning::CategorySummary& c : categories) {
    if (p.category_count == STATUS_MAX_CATEGORIES) break;
    p.categories[p.category_count++] = {c.label, c.views};
  }
  p.frames_done = stats.frames_done.load();
  p.drops = stats.total_drops();
  p.frame_p99_ns = stats.frame_latency.percentile(0.99);
  for (const engine::NodeStats& n : stats.nodes) {
    if (p.node_count == STATUS_MAX_NODES) break;
    p.nodes[p.node_count++] = {
        core::Text::from(n.name), n.processed.load(),        n.dropped.load(),
        n.deadline_misses.load(), n.service.percentile(0.5), n.service.percentile(0.99),
        n.service.max()};
  }
  p.published_ns = Clock::now().time_since_epoch().count();
}

}  // namespace

Result<GraphTopics, std::string> graph_topics(const std::string& graph) {
  GraphTopics topics;
  for (auto [topic, name] : {std::pair{&topics.objects, "orthoflow/" + graph + "/objects"},
                             std::pair{&topics.frames, "orthoflow/" + graph + "/frames"},
                             std::pair{&topics.commands, learning_commands_topic(graph)},
                             std::pair{&topics.acks, learning_acks_topic(graph)},
                             std::pair{&topics.status, status_topic(graph)}}) {
    auto parsed = engine::parse_topic(name);
    if (!parsed) return err(engine::to_string(parsed.error()));
    *topic = std::move(*parsed);
  }
  return topics;
}

struct LearningIpcBridge::Pending {
  std::uint64_t sequence = 0;  // the learning client's
  std::uint64_t client = 0, request = 0;
  LearningCommand command;
  Clock::time_point deadline;
};

Result<std::unique_ptr<LearningIpcBridge>, std::string> LearningIpcBridge::open(
    const std::string& graph, LearningService& learning, const engine::GraphStats& stats) {
  auto topics = graph_topics(graph);
  if (!topics) return err(topics.error());
  auto pools = engine::query_roudi_pools(std::chrono::milliseconds(2000));
  if (!pools) return err(engine::to_string(pools.error()));
  auto commands = engine::IpcSubscriber::create(
      topics->commands,
      {{LEARNING_COMMAND_TYPE_ID, LEARNING_IPC_VERSION}, engine::IpcPolicy::QUEUE, 64, 0});
  if (!commands) return err(engine::to_string(commands.error()));
  auto acks = engine::IpcPublisher::create(
      topics->acks,
      {{LEARNING_ACK_TYPE_ID, LEARNING_IPC_VERSION}, sizeof(LearningAckPayload), 0, false}, *pools);
  if (!acks) return err(engine::to_string(acks.error()));
  // History 1: a viewer that starts later sees the memory at once.
  auto status = engine::IpcPublisher::create(
      topics->status, {{STATUS_TYPE_ID, LEARNING_IPC_VERSION}, sizeof(StatusPayload), 1, false},
      *pools);
  if (!status) return err(engine::to_string(status.error()));
  auto client = learning.connect();
  if (!client) return err(std::string("the learning channel has no free client slot"));
  return std::unique_ptr<LearningIpcBridge>(
      new LearningIpcBridge(learning, stats, std::move(client), std::move(*commands),
                            std::move(*acks), std::move(*status)));
}

LearningIpcBridge::LearningIpcBridge(LearningService& learning, const engine::GraphStats& stats,
                                     std::unique_ptr<LearningClient> client,
                                     std::unique_ptr<engine::IpcSubscriber> commands,
                                     std::unique_ptr<engine::IpcPublisher> acks,
                                     std::unique_ptr<engine::IpcPublisher> status)
    : learning_(learning),
      stats_(stats),
      client_(std::move(client)),
      commands_(std::move(commands)),
      acks_(std::move(acks)),
      status_(std::move(status)) {
  thread_ = std::thread([this] { loop(); });
}

LearningIpcBridge::~LearningIpcBridge() {
  stop_.store(true);
  thread_.join();
}

// One pass every 2 ms (at most 64 commands each): new commands in, answers out, expired commands
// answered TIMEOUT, the status when due. Allocates (the status' category list): this thread is not
// on the frame path.
void LearningIpcBridge::loop() noexcept {
  std::vector<Pending> pending;
  pending.reserve(MAX_PENDING);
  auto status = std::make_unique<StatusPayload>();
  LearningAckPayload wire;
  auto answer = [&](const RemoteAck& ack) {
    encode_ack(ack, wire);
    publish(*acks_, wire);
    counters_.acks.fetch_add(1, std::memory_order_relaxed);
  };
  auto next_status = Clock::now();
  while (!stop_.load() && !engine::ipc_roudi_lost()) {
    for (std::size_t k = 0; k < MAX_PENDING; ++k) {  // bounded: the rest waits for the next pass
      auto taken = commands_->take();
      if (!taken) continue;  // a chunk with a wrong header: counted and released by the subscriber
      if (!taken->has_value()) break;
      counters_.commands.fetch_add(1, std::memory_order_relaxed);
      auto decoded = decode_command((*taken)->bytes());
      if (!decoded) {
        counters_.invalid.fetch_add(1, std::memory_order_relaxed);
        RemoteAck refusal{decoded.error().client,
                          decoded.error().request,
                          AckStatus::INVALID,
                          decoded.error().problem,
                          {}};
        answer(refusal);
        continue;
      }
      const std::uint64_t sequence =
          pending.size() < MAX_PENDING ? client_->send(decoded->command) : 0;
      if (sequence == 0) {
        RemoteAck full{decoded->client, decoded->request, AckStatus::QUEUE_FULL, 0, {}};
        full.ack.kind = decoded->command.kind;
        answer(full);
        continue;
      }
      pending.push_back({sequence, decoded->client, decoded->request, decoded->command,
                         Clock::now() + ANSWER_TIMEOUT});
    }
    LearningAck ack;
    while (client_->poll(ack)) {
      const auto it = std::find_if(pending.begin(), pending.end(),
                                   [&](const Pending& p) { return p.sequence == ack.sequence; });
      if (it == pending.end()) continue;  // answered TIMEOUT already
      answer({it->client, it->request, AckStatus::ACKNOWLEDGED, 0, ack});
      pending.erase(it);
    }
    const auto now = Clock::now();
    for (auto it = pending.begin(); it != pending.end();) {
      if (it->deadline > now) {
        ++it;
        continue;
      }
      RemoteAck late{it->client, it->request, AckStatus::TIMEOUT, 0, {}};
      late.ack.kind = it->command.kind;
      late.ack.track_id = it->command.track_id;
      answer(late);
      counters_.timeouts.fetch_add(1, std::memory_order_relaxed);
      it = pending.erase(it);
    }
    if (now >= next_status) {
      try {
        fill_status(learning_, stats_, *status);
        publish(*status_, *status);
        counters_.statuses.fetch_add(1, std::memory_order_relaxed);
      } catch (const std::exception&) {  // out of memory for the category list: try next time
      }
      next_status = now + STATUS_PERIOD;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

}  // namespace orthoflow::graphs
