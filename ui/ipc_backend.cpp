#include "ui/ipc_backend.hpp"

#include <chrono>
#include <cstring>
#include <optional>

#include "engine/ipc_pubsub.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/services/learning_ipc_bridge.hpp"
#include "ui/background_thread.hpp"

namespace orthoflow::ui {

namespace {

using Clock = std::chrono::steady_clock;

std::int64_t now_ns() { return Clock::now().time_since_epoch().count(); }

Result<std::unique_ptr<engine::IpcSubscriber>, std::string> subscribe(const engine::IpcTopic& topic,
                                                                      engine::IpcPayloadType type,
                                                                      engine::IpcPolicy policy,
                                                                      std::uint64_t depth,
                                                                      std::uint64_t history) {
  auto s = engine::IpcSubscriber::create(topic, {type, policy, depth, history});
  if (!s) return err(engine::to_string(s.error()));
  return std::move(*s);
}

// The next sample of @p in, if any; one the subscriber refused (its header) counts in @p rejected.
std::optional<engine::IpcSample> next_sample(engine::IpcSubscriber& in,
                                             std::atomic<std::uint64_t>& rejected) {
  auto taken = in.take();
  if (!taken) {
    rejected.fetch_add(1, std::memory_order_relaxed);
    return std::nullopt;
  }
  return std::move(*taken);
}

}  // namespace

Result<std::unique_ptr<IpcBackend>, std::string> IpcBackend::open(const std::string& graph) {
  auto topics = graphs::graph_topics(graph);
  if (!topics) return err(topics.error());
  auto objects =
      subscribe(topics->objects, {engine::OBJECT_LIST_TYPE_ID, engine::OBJECT_LIST_VERSION},
                engine::IpcPolicy::LATEST, 1, 0);
  if (!objects) return err(objects.error());
  auto status = subscribe(topics->status, {graphs::STATUS_TYPE_ID, graphs::LEARNING_IPC_VERSION},
                          engine::IpcPolicy::LATEST, 1, 1);
  if (!status) return err(status.error());
  auto acks = subscribe(topics->acks, {graphs::LEARNING_ACK_TYPE_ID, graphs::LEARNING_IPC_VERSION},
                        engine::IpcPolicy::QUEUE, 64, 0);
  if (!acks) return err(acks.error());
  auto pools = engine::query_roudi_pools(std::chrono::milliseconds(2000));
  if (!pools) return err(engine::to_string(pools.error()));
  auto commands = engine::IpcPublisher::create(
      topics->commands,
      {{graphs::LEARNING_COMMAND_TYPE_ID, graphs::LEARNING_IPC_VERSION},
       sizeof(graphs::LearningCommandPayload),
       0,
       false},
      *pools);
  if (!commands) return err(engine::to_string(commands.error()));
  return std::unique_ptr<IpcBackend>(new IpcBackend(std::move(*objects), std::move(*status),
                                                    std::move(*acks), std::move(*commands)));
}

IpcBackend::IpcBackend(std::unique_ptr<engine::IpcSubscriber> objects,
                       std::unique_ptr<engine::IpcSubscriber> status,
                       std::unique_ptr<engine::IpcSubscriber> acks,
                       std::unique_ptr<engine::IpcPublisher> commands)
    : objects_in_(std::move(objects)),
      status_in_(std::move(status)),
      acks_in_(std::move(acks)),
      commands_out_(std::move(commands)),
      client_id_(random_client_id()),
      latest_(std::make_unique<engine::ObjectListPayload>()) {
  latest_->reset_header();
  poller_ = std::thread([this] { poll(); });
}

IpcBackend::~IpcBackend() {
  stop_.store(true);
  poller_.join();
}

void IpcBackend::poll() noexcept {
  make_this_thread_background();
  while (!stop_.load() && !engine::ipc_roudi_lost()) {
    try {
      take_objects();
      take_status();
      take_acks();
    } catch (const std::exception&) {  // out of memory for a status: the page keeps the last one
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

void IpcBackend::take_objects() {
  const auto sample = next_sample(*objects_in_, counters_.rejected);
  if (!sample) return;
  const auto bytes = sample->bytes();
  if (bytes.size() < sizeof(engine::ObjectListPayload)) {
    counters_.rejected.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  std::lock_guard<std::mutex> guard(state_lock_);
  std::memcpy(latest_.get(), bytes.data(), sizeof(engine::ObjectListPayload));
  objects_at_ns_ = now_ns();
  counters_.object_lists.fetch_add(1, std::memory_order_relaxed);
}

void IpcBackend::take_status() {
  const auto sample = next_sample(*status_in_, counters_.rejected);
  if (!sample) return;
  auto decoded = graphs::decode_status(sample->bytes());
  if (!decoded) {
    counters_.rejected.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  durable_.store(decoded->durable);
  std::lock_guard<std::mutex> guard(state_lock_);
  status_ = std::move(*decoded);
  status_at_ns_ = now_ns();
  counters_.statuses.fetch_add(1, std::memory_order_relaxed);
}

void IpcBackend::take_acks() {
  for (int k = 0; k < 64; ++k) {  // the queue's depth: bounded per pass
    const auto sample = next_sample(*acks_in_, counters_.rejected);
    if (!sample) return;
    auto decoded = graphs::decode_ack(sample->bytes());
    if (!decoded) {
      counters_.rejected.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (decoded->client != client_id_) continue;  // another sender's
    std::lock_guard<std::mutex> guard(state_lock_);
    const auto it = awaited_.find(decoded->request);
    if (it == awaited_.end()) continue;  // answered after its submit() gave up
    it->second = *decoded;
    counters_.acks.fetch_add(1, std::memory_order_relaxed);
    answered_.notify_all();
  }
}

bool IpcBackend::connected() const {
  std::lock_guard<std::mutex> guard(state_lock_);
  return status_at_ns_ != 0 && now_ns() - status_at_ns_ < STALE_AFTER_NS;
}

UiSnapshot IpcBackend::snapshot() const {
  UiSnapshot s;
  s.durable = durable();
  s.events = events_.events();
  std::lock_guard<std::mutex> guard(state_lock_);
  const std::int64_t now = now_ns();
  if (objects_at_ns_ != 0 && now - objects_at_ns_ < STALE_AFTER_NS) {
    s.frame_id = latest_->frame_id;
    s.age_ns = latest_->age_ns;
    s.table_reason = latest_->table_reason;
    s.gravity = latest_->gravity;
    s.objects = object_views(*latest_);
  }
  if (status_at_ns_ != 0 && now - status_at_ns_ < STALE_AFTER_NS) {
    for (const graphs::StatusCategory& c : status_.categories) {
      std::string label(c.label.view());
      const std::int64_t taught = events_.last_taught_ms(label);
      s.memory.push_back({std::move(label), static_cast<std::size_t>(c.views), taught});
    }
    s.frames_done = status_.frames_done;
    s.drops = status_.drops;
    s.frame_p99_ns = status_.frame_p99_ns;
    for (const graphs::StatusNode& n : status_.nodes) {
      s.nodes.push_back({std::string(n.name.view()), n.processed, n.dropped, n.deadline_misses,
                         n.p50_ns, n.p99_ns, n.max_ns});
    }
  }
  return s;
}

UiAnswer IpcBackend::submit(const UiAction& action, int timeout_ms) {
  UiAnswer answer;  // TIMEOUT
  graphs::LearningCommand command;
  command.kind = action.kind;
  command.track_id = action.track;
  command.label = action.label;
  graphs::LearningCommandPayload wire;
  std::uint64_t request = 0;
  bool sent = false;
  {
    std::lock_guard<std::mutex> guard(send_lock_);
    request = next_request_++;
    if (!graphs::encode_command(command, client_id_, request, wire)) {
      answer = {UiAnswer::Status::ACKNOWLEDGED, {}};
      answer.ack.kind = action.kind;
      answer.ack.outcome = graphs::LearningAck::Outcome::BAD_LABEL;
    } else if (commands_out_->has_subscribers()) {
      {
        std::lock_guard<std::mutex> state(state_lock_);
        awaited_.emplace(request, std::nullopt);
      }
      sent = commands_out_
                 ->publish_copy(std::span<const std::byte>(
                     reinterpret_cast<const std::byte*>(&wire), sizeof wire))
                 .has_value();
    }
  }
  if (sent) {
    std::unique_lock<std::mutex> state(state_lock_);
    answered_.wait_for(state, std::chrono::milliseconds(timeout_ms),
                       [&] { return awaited_[request].has_value(); });
    const std::optional<graphs::RemoteAck> got = awaited_[request];
    awaited_.erase(request);
    state.unlock();
    if (got) {
      switch (got->status) {
        case graphs::AckStatus::ACKNOWLEDGED:
          answer = {UiAnswer::Status::ACKNOWLEDGED, got->ack};
          break;
        case graphs::AckStatus::QUEUE_FULL:
          answer.status = UiAnswer::Status::QUEUE_FULL;
          break;
        case graphs::AckStatus::INVALID:  // this side validated already: a version mismatch
          answer = {UiAnswer::Status::ACKNOWLEDGED, got->ack};
          answer.ack.outcome = graphs::LearningAck::Outcome::BAD_LABEL;
          break;
        case graphs::AckStatus::TIMEOUT:
          break;
      }
    }
  } else if (answer.status == UiAnswer::Status::TIMEOUT) {
    std::lock_guard<std::mutex> state(state_lock_);
    awaited_.erase(request);
  }
  events_.record(action, answer);
  return answer;
}

}  // namespace orthoflow::ui
