#include "engine/ipc_nodes.hpp"

#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#include "engine/frame_payload.hpp"
#include "engine/ipc_frame_ref.hpp"
#include "engine/object_list_payload.hpp"

namespace orthoflow::engine {

namespace {

using Made = Result<std::unique_ptr<Node>, std::string>;

std::int64_t now_ms() noexcept {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Polls RouDi's socket at most every 100 ms: a dead RouDi cannot hand out or reclaim chunks any
// more, so the node stops (source: END) and the process reports it (ipc_roudi_lost()).
class Liveness {
 public:
  bool alive() noexcept {
    const std::int64_t now = now_ms();
    if (now - last_ms_ < 100) return true;
    last_ms_ = now;
    if (probe_roudi()) return true;
    mark_roudi_lost();
    return false;
  }

 private:
  std::int64_t last_ms_ = 0;
};

/// Sink: copies each payload once into a loaned chunk and publishes it.
class IpcPublishNode final : public IpcNode {
 public:
  IpcPublishNode(std::unique_ptr<IpcPublisher> publisher, const std::string& type)
      : publisher_(std::move(publisher)), inputs_{{"in", type, true}} {}
  std::span<const PortSpec> inputs() const noexcept override { return inputs_; }
  std::span<const PortSpec> outputs() const noexcept override { return {}; }
  bool stateful() const noexcept override { return true; }  // a publisher is single-threaded
  void process(const Message& in, Emitter& /*out*/) noexcept override {
    if (!liveness_.alive()) return;
    if (in.skipped || !in.payload) return;
    const auto bytes = resolve_frame_bytes(in.payload.bytes());
    // Failures (pool exhausted, bad header) are counted in the publisher's counters; no I/O here.
    auto published = publisher_->publish_copy(bytes);
    static_cast<void>(published);
  }
  const std::string& topic() const noexcept override { return publisher_->topic(); }
  const IpcCounters& ipc_counters() const noexcept override { return publisher_->counters(); }

 private:
  std::unique_ptr<IpcPublisher> publisher_;
  std::vector<PortSpec> inputs_;
  Liveness liveness_;
};

/// Source: one frame per received chunk; the frame's block holds a FrameRef to the chunk.
class IpcSubscribeNode final : public IpcNode {
 public:
  struct Settings {
    std::int64_t frames = 0;    // END after this many frames (0 = endless)
    std::int64_t idle_ms = 0;   // END after this long without data (0 = never)
    std::int64_t wait_ms = 100; // longest wait inside produce() before an idle tombstone
  };
  IpcSubscribeNode(std::unique_ptr<IpcSubscriber> subscriber, const std::string& type, const Settings& settings,
                   const NodeContext& context)
      : subscriber_(std::move(subscriber)), outputs_{{"out", type, false}}, settings_(settings), context_(context),
        held_(context.pool->block_count()), last_data_ms_(now_ms()) {}
  ~IpcSubscribeNode() override {
    for (Held& held : held_) held.sample.reset();  // chunks back to iceoryx before the subscriber goes
  }
  std::span<const PortSpec> inputs() const noexcept override { return {}; }
  std::span<const PortSpec> outputs() const noexcept override { return outputs_; }
  bool stateful() const noexcept override { return true; }
  void process(const Message& /*in*/, Emitter& /*out*/) noexcept override {}
  SourceStatus produce(Message& out) noexcept override;
  const std::string& topic() const noexcept override { return subscriber_->topic(); }
  const IpcCounters& ipc_counters() const noexcept override { return subscriber_->counters(); }

 private:
  struct Held {
    memory_pool::BlockHandle block;  // our reference to the block holding the FrameRef
    IpcSample sample;                // the chunk it points at
  };
  void sweep() noexcept;
  bool hand_over(IpcSample sample, Message& out) noexcept;

  std::unique_ptr<IpcSubscriber> subscriber_;
  std::vector<PortSpec> outputs_;
  Settings settings_;
  NodeContext context_;
  std::vector<Held> held_;  // by block index; sized once at start-up
  std::int64_t produced_ = 0;
  std::int64_t last_data_ms_;
  Liveness liveness_;
};

// A chunk is released as soon as no message holds its block any more: we keep one handle, so a
// use count of 1 means every reader is done (nobody else can take a new reference).
void IpcSubscribeNode::sweep() noexcept {
  for (Held& held : held_) {
    if (held.block && held.block.use_count() == 1) {
      held.sample.reset();
      held.block.reset();
    }
  }
}

bool IpcSubscribeNode::hand_over(IpcSample sample, Message& out) noexcept {
  auto block_result = context_.pool->acquire(context_.name, sizeof(FrameRef));
  if (!block_result) return false;  // pool exhausted: the sample is released, the frame dropped
  FrameRef ref;
  ref.data = sample.bytes().data();
  ref.size = sample.bytes().size();
  ref.sequence = sample.sequence();
  std::memcpy(block_result->bytes().data(), &ref, sizeof(ref));
  Held& held = held_[block_result->index()];
  held.sample = std::move(sample);
  held.block = *block_result;
  out.payload = std::move(*block_result);
  out.value = static_cast<std::int64_t>(ref.sequence);
  return true;
}

SourceStatus IpcSubscribeNode::produce(Message& out) noexcept {
  if (settings_.frames > 0 && produced_ >= settings_.frames) return SourceStatus::END;
  sweep();
  const std::int64_t start = now_ms();
  while (true) {
    auto taken = subscriber_->take();
    if (taken && taken->has_value()) {
      last_data_ms_ = now_ms();
      ++produced_;
      if (!hand_over(std::move(**taken), out)) out.skipped = true;
      return SourceStatus::FRAME;
    }
    if (!liveness_.alive()) return SourceStatus::END;
    const std::int64_t now = now_ms();
    if (settings_.idle_ms > 0 && now - last_data_ms_ >= settings_.idle_ms) return SourceStatus::END;
    if (now - start >= settings_.wait_ms) {  // give the engine a chance to see a stop request
      out.skipped = true;
      return SourceStatus::FRAME;
    }
    if (!taken) continue;  // a rejected chunk (counted): look at the next one at once
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
}

// ParamMap has typed getters for numbers and choices only; topics and paths are free text.
std::string text_param(const ParamMap& params, const std::string& key, const std::string& fallback) {
  for (const auto& entry : params.entries()) {
    if (entry.key == key) return entry.value;
  }
  return fallback;
}

Result<IpcPools, std::string> pools_for(const ParamMap& params) {
  const std::string path = text_param(params, "roudi_config", "");
  auto pools_result = path.empty() ? query_roudi_pools(std::chrono::milliseconds(2000)) : load_roudi_pools(path);
  if (!pools_result) return err(to_string(pools_result.error()));
  return *pools_result;
}

Result<IpcTopic, std::string> start(const ParamMap& params) {
  auto topic_result = parse_topic(text_param(params, "topic", ""));
  if (!topic_result) return err(to_string(topic_result.error()));
  if (auto init = init_ipc_runtime("orthoflow_" + std::to_string(::getpid())); !init) {
    return err(to_string(init.error()));
  }
  return *topic_result;
}

Made make_publish(const ParamMap& params, const NodeContext& context) {
  if (auto ok = params.only({"topic", "type", "history", "lossless", "max_bytes", "roudi_config"}); !ok) {
    return err(ok.error());
  }
  auto type_result = params.choice("type", "frame", {"frame", "objects"});
  if (!type_result) return err(type_result.error());
  IpcPublisherConfig config;
  config.type = *ipc_payload_type(*type_result);
  auto history = params.integer("history", 0, 0, 16);
  auto lossless = params.integer("lossless", 0, 0, 1);
  const auto block = static_cast<std::int64_t>(context.pool ? context.pool->block_bytes() : 4096);
  auto max_bytes = params.integer("max_bytes", block, 56, std::int64_t{1} << 30);
  if (!history) return err(history.error());
  if (!lossless) return err(lossless.error());
  if (!max_bytes) return err(max_bytes.error());
  config.history = static_cast<std::uint64_t>(*history);
  config.lossless = *lossless == 1;
  config.max_payload_bytes = static_cast<std::uint64_t>(*max_bytes);
  auto topic = start(params);
  if (!topic) return err(topic.error());
  auto pools = pools_for(params);
  if (!pools) return err(pools.error());
  auto publisher = IpcPublisher::create(*topic, config, *pools);
  if (!publisher) return err(to_string(publisher.error()));
  return std::unique_ptr<Node>(new IpcPublishNode(std::move(*publisher), *type_result));
}

Made make_subscribe(const ParamMap& params, const NodeContext& context) {
  if (auto ok = params.only({"topic", "type", "policy", "depth", "history", "frames", "idle_ms", "wait_ms"}); !ok) {
    return err(ok.error());
  }
  auto type_result = params.choice("type", "frame", {"frame", "objects"});
  auto policy = params.choice("policy", "latest", {"latest", "queue", "lossless"});
  if (!type_result) return err(type_result.error());
  if (!policy) return err(policy.error());
  const auto blocks = static_cast<std::int64_t>(context.pool ? context.pool->block_count() : 0);
  // iceoryx lets a subscriber hold 256 chunks: one per pool block plus the queue must fit.
  auto depth = params.integer("depth", 1, 1, std::max<std::int64_t>(1, 256 - blocks));
  auto history = params.integer("history", 0, 0, 16);
  auto frames = params.integer("frames", 0, 0, std::int64_t{1} << 40);
  auto idle = params.integer("idle_ms", 0, 0, 86'400'000);
  auto wait = params.integer("wait_ms", 100, 1, 10'000);
  for (const auto* r : {&depth, &history, &frames, &idle, &wait}) {
    if (!*r) return err(r->error() + (r == &depth ? " (256 minus the pool's blocks)" : ""));
  }
  if (context.pool == nullptr || blocks > 255) return err(std::string("ipc_subscribe: needs a pool of 1..255 blocks"));
  IpcSubscriberConfig config{*ipc_payload_type(*type_result),
                             *policy == "latest" ? IpcPolicy::LATEST
                                                 : (*policy == "queue" ? IpcPolicy::QUEUE : IpcPolicy::LOSSLESS),
                             static_cast<std::uint64_t>(*depth), static_cast<std::uint64_t>(*history)};
  auto topic = start(params);
  if (!topic) return err(topic.error());
  auto subscriber = IpcSubscriber::create(*topic, config);
  if (!subscriber) return err(to_string(subscriber.error()));
  return std::unique_ptr<Node>(new IpcSubscribeNode(std::move(*subscriber), *type_result,
                                                    IpcSubscribeNode::Settings{*frames, *idle, *wait}, context));
}

}  // namespace

Result<IpcPayloadType, std::string> ipc_payload_type(const std::string& port_type) {
  if (port_type == "frame") return IpcPayloadType{FRAME_TYPE_ID, FRAME_VERSION};
  if (port_type == "objects") return IpcPayloadType{OBJECT_LIST_TYPE_ID, OBJECT_LIST_VERSION};
  return err("IPC payload type '" + port_type + "': expected frame or objects");
}

void add_ipc_nodes(NodeRegistry& registry) {
  registry.add("ipc_publish",
               "sink: topic=service/instance/event, type=frame|objects, history, lossless=0|1, max_bytes, "
               "roudi_config=PATH (else RouDi's live pools); copies each payload once into a chunk",
               make_publish);
  registry.add("ipc_subscribe",
               "source: topic, type=frame|objects, policy=latest|queue|lossless, depth, history, frames, idle_ms, "
               "wait_ms; zero-copy (the block holds a FrameRef to the chunk)",
               make_subscribe);
}

}  // namespace orthoflow::engine
