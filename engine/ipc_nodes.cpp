#include "engine/ipc_nodes.hpp"

#include <unistd.h>

#include <chrono>
#include <cstring>
#include <optional>
#include <thread>
#include <vector>

#include "engine/frame_payload.hpp"
#include "engine/ipc_frame_ref.hpp"
#include "engine/ipc_node_params.hpp"
#include "engine/object_list_payload.hpp"

namespace orthoflow::engine {

namespace {

using Made = Result<std::unique_ptr<Node>, std::string>;

std::int64_t now_ms() noexcept {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
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
    if (in.skipped || !in.payload) return;
    if (!liveness_.alive()) {  // counted, so that a summary never claims it was sent
      publisher_->count_unpublished();
      return;
    }
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
  IpcSubscribeNode(std::unique_ptr<IpcSubscriber> subscriber, const IpcSubscribeParams& settings,
                   const NodeContext& context)
      : subscriber_(std::move(subscriber)),
        outputs_{{"out", settings.type, false}},
        settings_(settings),
        context_(context),
        held_(context.pool->block_count()),
        last_data_ms_(now_ms()) {}
  ~IpcSubscribeNode() override {
    for (Held& held : held_)
      held.sample.reset();  // chunks back to iceoryx before the subscriber goes
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
  IpcSubscribeParams settings_;
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

/// BuildMode::CHECK: an IPC kind's ports, topic and serial flag, attached to nothing. The Engine
/// refuses CHECK graphs, so process() and produce() never run.
class IpcCheckedNode final : public IpcNode {
 public:
  IpcCheckedNode(std::string topic, std::vector<PortSpec> inputs, std::vector<PortSpec> outputs)
      : topic_(std::move(topic)), inputs_(std::move(inputs)), outputs_(std::move(outputs)) {}
  std::span<const PortSpec> inputs() const noexcept override { return inputs_; }
  std::span<const PortSpec> outputs() const noexcept override { return outputs_; }
  bool stateful() const noexcept override { return true; }
  void process(const Message& /*in*/, Emitter& /*out*/) noexcept override {}
  const std::string& topic() const noexcept override { return topic_; }
  const IpcCounters& ipc_counters() const noexcept override { return counters_; }

 private:
  std::string topic_;
  std::vector<PortSpec> inputs_, outputs_;
  IpcCounters counters_;
};

Result<void, std::string> connect_runtime() {
  if (auto init = init_ipc_runtime("orthoflow_" + std::to_string(::getpid())); !init) {
    return err(to_string(init.error()));
  }
  return {};
}

// A RouDi TOML file named by roudi_config is read and checked in both modes, before connecting: it
// must parse and hold a chunk for max_bytes (iceoryx aborts on a loan larger than every pool).
// Without it RouDi's live pools are known only once connected, so that check waits for RUN.
Result<std::optional<IpcPools>, std::string> named_pools(const IpcPublishParams& parsed) {
  if (parsed.roudi_config.empty()) return std::optional<IpcPools>{};
  auto pools_result = load_roudi_pools(parsed.roudi_config);
  if (!pools_result) return err(to_string(pools_result.error()));
  auto fits = check_pool_fits(*pools_result, parsed.config.max_payload_bytes, PAYLOAD_ALIGNMENT,
                              "publisher " + parsed.topic.str());
  if (!fits) return err(to_string(fits.error()));
  return std::optional<IpcPools>(std::move(*pools_result));
}

Made make_publish(const ParamMap& params, const NodeContext& context) {
  auto parsed = parse_ipc_publish_params(params, context);
  if (!parsed) return err(parsed.error());
  auto maybe_pools_result = named_pools(*parsed);
  if (!maybe_pools_result) return err(maybe_pools_result.error());
  if (context.mode == BuildMode::CHECK) {
    return std::unique_ptr<Node>(
        new IpcCheckedNode(parsed->topic.str(), {{"in", parsed->type, true}}, {}));
  }
  if (auto connected = connect_runtime(); !connected) return err(connected.error());
  auto pools_result = maybe_pools_result->has_value()
                          ? Result<IpcPools, IpcError>(**maybe_pools_result)
                          : query_roudi_pools(std::chrono::milliseconds(2000));
  if (!pools_result) return err(to_string(pools_result.error()));
  auto publisher = IpcPublisher::create(parsed->topic, parsed->config, *pools_result);
  if (!publisher) return err(to_string(publisher.error()));
  return std::unique_ptr<Node>(new IpcPublishNode(std::move(*publisher), parsed->type));
}

Made make_subscribe(const ParamMap& params, const NodeContext& context) {
  auto parsed = parse_ipc_subscribe_params(params, context);
  if (!parsed) return err(parsed.error());
  if (context.mode == BuildMode::CHECK) {
    return std::unique_ptr<Node>(
        new IpcCheckedNode(parsed->topic.str(), {}, {{"out", parsed->type, false}}));
  }
  if (auto connected = connect_runtime(); !connected) return err(connected.error());
  auto subscriber = IpcSubscriber::create(parsed->topic, parsed->config);
  if (!subscriber) return err(to_string(subscriber.error()));
  return std::unique_ptr<Node>(new IpcSubscribeNode(std::move(*subscriber), *parsed, context));
}

}  // namespace

Result<IpcPayloadType, std::string> ipc_payload_type(const std::string& port_type) {
  if (port_type == "frame") return IpcPayloadType{FRAME_TYPE_ID, FRAME_VERSION};
  if (port_type == "objects") return IpcPayloadType{OBJECT_LIST_TYPE_ID, OBJECT_LIST_VERSION};
  return err("IPC payload type '" + port_type + "': expected frame or objects");
}

void add_ipc_nodes(NodeRegistry& registry) {
  registry.add(
      "ipc_publish",
      "sink: topic=service/instance/event, type=frame|objects, history, lossless=0|1, max_bytes, "
      "roudi_config=PATH (else RouDi's live pools); copies each payload once into a chunk",
      make_publish);
  registry.add("ipc_subscribe",
               "source: topic, type=frame|objects, policy=latest|queue|lossless, depth, history, "
               "frames, idle_ms, "
               "wait_ms; zero-copy (the block holds a FrameRef to the chunk)",
               make_subscribe);
}

}  // namespace orthoflow::engine
