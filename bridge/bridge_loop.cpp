#include "bridge/bridge_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "engine/frame_payload.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/services/learning_ipc_bridge.hpp"

namespace orthoflow::bridge {
namespace {

std::int64_t steady_now_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

engine::NodeStats* add_row(engine::GraphStats& stats, const char* name) {
  engine::NodeStats& n = stats.nodes.emplace_back();
  n.name = name;
  n.sink = true;
  return &n;
}

}  // namespace

Result<std::unique_ptr<BridgeLoop>, std::string> BridgeLoop::open(const BridgeConfig& config,
                                                                  std::uint64_t client) {
  if (client == 0) return err(std::string("the bridge needs a non-zero client id"));
  auto topics = graphs::graph_topics(config.graph);
  if (!topics) return err(topics.error());
  std::unique_ptr<BridgeLoop> b(new BridgeLoop());
  b->config_ = config;
  b->list_ = std::make_unique<engine::ObjectListPayload>();
  b->relay_ = std::make_unique<CommandRelay>(client, config.ack_timeout_ms * 1'000'000);
  const auto ipc = [](const std::string& what, const engine::IpcError& e) {
    return what + ": " + engine::to_string(e);
  };
  auto objects = engine::IpcSubscriber::create(
      topics->objects, {{engine::OBJECT_LIST_TYPE_ID, engine::OBJECT_LIST_VERSION},
                        engine::IpcPolicy::QUEUE,
                        16,
                        0});
  if (!objects) return err(ipc("objects", objects.error()));
  b->objects_ = std::move(*objects);
  if (config.frames) {
    auto frames = engine::IpcSubscriber::create(
        topics->frames,
        {{engine::FRAME_TYPE_ID, engine::FRAME_VERSION}, engine::IpcPolicy::LATEST, 1, 0});
    if (!frames) return err(ipc("frames", frames.error()));
    b->frames_ = std::move(*frames);
  }
  auto acks = engine::IpcSubscriber::create(
      topics->acks, {{graphs::LEARNING_ACK_TYPE_ID, graphs::LEARNING_IPC_VERSION},
                     engine::IpcPolicy::QUEUE,
                     64,
                     0});
  if (!acks) return err(ipc("acks", acks.error()));
  b->acks_ = std::move(*acks);
  auto pools = engine::query_roudi_pools(std::chrono::milliseconds(2000));
  if (!pools) return err(ipc("RouDi's pools", pools.error()));
  auto commands = engine::IpcPublisher::create(
      topics->commands,
      {{graphs::LEARNING_COMMAND_TYPE_ID, graphs::LEARNING_IPC_VERSION},
       sizeof(graphs::LearningCommandPayload),
       0,
       false},
      *pools);
  if (!commands) return err(ipc("learning commands", commands.error()));
  b->commands_ = std::move(*commands);
  auto arm_stop = ArmStopRelay::open(*pools);
  if (!arm_stop) return err(arm_stop.error());
  b->arm_stop_ = std::move(*arm_stop);
  auto ros = RosEndpoints::open(config);
  if (!ros) return err(ros.error());
  b->ros_ = std::move(*ros);
  b->stats_.name = "dds_bridge";
  b->objects_stats_ = add_row(b->stats_, "objects");
  b->points_stats_ = add_row(b->stats_, "points");
  b->commands_stats_ = add_row(b->stats_, "commands");
  b->acks_stats_ = add_row(b->stats_, "acks");
  return b;
}

BridgeLoop::~BridgeLoop() {
  // DDS first (it may reference nothing of iceoryx, but this keeps the order of open() reversed).
  ros_.reset();
}

std::size_t BridgeLoop::pump(std::int64_t now_ns) {
  if (start_ns_ == 0) start_ns_ = now_ns;
  std::size_t work = pump_objects(now_ns);
  if (frames_) work += pump_frame(now_ns);
  work += pump_commands(now_ns);
  work += pump_acks(now_ns);
  work += arm_stop_->pump(*ros_, now_ns);
  counters_.arm_stops_in = arm_stop_->stops_in();
  counters_.arm_stops_confirmed = arm_stop_->stops_confirmed();
  // The engine's graph row: object lists are the bridge's frames.
  stats_.elapsed_ns.store(now_ns - start_ns_, std::memory_order_relaxed);
  stats_.frames_in.store(objects_stats_->processed.load(), std::memory_order_relaxed);
  stats_.frames_done.store(counters_.objects_out, std::memory_order_relaxed);
  return work;
}

std::size_t BridgeLoop::pump_objects(std::int64_t /*now_ns*/) {
  std::size_t n = 0;
  for (; n < 16; ++n) {
    auto taken = objects_->take();
    if (!taken) continue;  // a chunk of another type: counted by the subscriber (rejected)
    if (!taken->has_value()) break;
    const auto bytes = (*taken)->bytes();
    if (bytes.size() < sizeof(engine::ObjectListPayload)) continue;
    std::memcpy(static_cast<void*>(list_.get()), bytes.data(), sizeof(engine::ObjectListPayload));
    taken->reset();  // the chunk back to the graph's pool before DDS serialises
    const std::int64_t t0 = steady_now_ns();
    auto written = ros_->write_objects(*list_);
    const std::int64_t t1 = steady_now_ns();
    objects_stats_->processed.fetch_add(1, std::memory_order_relaxed);
    if (!written) {
      ++counters_.write_errors;
      continue;
    }
    ++counters_.objects_out;
    counters_.data_bytes_out += *written;
    objects_stats_->service.record(t1 - t0);
    if (list_->host_stamp_ns > 0) objects_stats_->age.record(t1 - list_->host_stamp_ns);
  }
  objects_stats_->dropped.store(objects_->counters().dropped.load(), std::memory_order_relaxed);
  return n;
}

std::size_t BridgeLoop::pump_frame(std::int64_t now_ns) {
  auto taken = frames_->take();
  if (!taken || !taken->has_value()) return 0;
  // A token bucket of two frames refilled at max_frame_hz: the rate is held on average, and a
  // frame that comes a little early after a late one is not thinned (graphs jitter).
  if (config_.max_frame_hz > 0.0) {
    if (last_frame_ns_ != 0)
      frame_tokens_ =
          std::min(2.0, frame_tokens_ + 1e-9 * static_cast<double>(now_ns - last_frame_ns_) *
                                            config_.max_frame_hz);
    last_frame_ns_ = now_ns;
    if (frame_tokens_ < 1.0) {
      ++counters_.frames_thinned;
      return 1;
    }
    frame_tokens_ -= 1.0;
  }
  auto view = engine::view_frame((*taken)->bytes());
  if (!view) {
    ++counters_.frames_bad;
    return 1;
  }
  const std::int64_t t0 = steady_now_ns();
  auto written = ros_->write_frame(*view);
  const std::int64_t t1 = steady_now_ns();
  points_stats_->processed.fetch_add(1, std::memory_order_relaxed);
  if (!written) {
    ++counters_.write_errors;
    return 1;
  }
  ++counters_.frames_out;
  counters_.data_bytes_out += *written;
  points_stats_->service.record(t1 - t0);
  if (view->header->host_stamp_ns > 0) points_stats_->age.record(t1 - view->header->host_stamp_ns);
  points_stats_->dropped.store(frames_->counters().dropped.load(), std::memory_order_relaxed);
  return 1;
}

std::size_t BridgeLoop::pump_commands(std::int64_t now_ns) {
  return ros_->take_commands(64, [&](const RosLearningCommand& command) {
    const std::int64_t t0 = steady_now_ns();
    ++counters_.commands_in;
    commands_stats_->processed.fetch_add(1, std::memory_order_relaxed);
    RelayDecision d = relay_->on_command(command, now_ns, commands_->has_subscribers());
    if (d.forward) {
      auto sent = commands_->publish_copy(
          std::as_bytes(std::span<const graphs::LearningCommandPayload, 1>(&d.payload, 1)));
      if (sent) {
        ++counters_.commands_forwarded;
        commands_stats_->service.record(steady_now_ns() - t0);
        return;
      }
      // iceoryx had no chunk: the command waits for an ack that will not come; answer now.
      relay_->cancel(d.bridge_request);
      d.answer.status = graphs::AckStatus::QUEUE_FULL;
      d.problem = "iceoryx had no chunk for the command: send again";
    }
    if (d.answer.status == graphs::AckStatus::INVALID) ++counters_.commands_invalid;
    if (d.answer.status == graphs::AckStatus::TIMEOUT) ++counters_.commands_no_graph;
    if (d.answer.status == graphs::AckStatus::QUEUE_FULL) ++counters_.commands_queue_full;
    commands_stats_->dropped.fetch_add(1, std::memory_order_relaxed);
    if (ros_->write_ack(d.answer, d.route, d.problem))
      ++counters_.acks_out;
    else
      ++counters_.write_errors;
  });
}

std::size_t BridgeLoop::pump_acks(std::int64_t now_ns) {
  std::size_t n = 0;
  for (; n < 64; ++n) {
    auto taken = acks_->take();
    if (!taken) continue;
    if (!taken->has_value()) break;
    auto ack = graphs::decode_ack((*taken)->bytes());
    if (!ack) continue;
    const auto route = relay_->on_ack(*ack);
    if (!route) continue;  // another client's
    const std::int64_t t0 = steady_now_ns();
    if (ros_->write_ack(*ack, *route, ""))
      ++counters_.acks_out;
    else
      ++counters_.write_errors;
    acks_stats_->processed.fetch_add(1, std::memory_order_relaxed);
    acks_stats_->service.record(steady_now_ns() - t0);
  }
  while (const auto route = relay_->next_expired(now_ns)) {
    graphs::RemoteAck timeout;
    timeout.status = graphs::AckStatus::TIMEOUT;
    if (ros_->write_ack(timeout, *route, "the graph did not answer in time")) ++counters_.acks_out;
    ++counters_.acks_timeout;
    acks_stats_->dropped.fetch_add(1, std::memory_order_relaxed);
  }
  return n;
}

std::string BridgeLoop::ipc_lines() const {
  std::string out;
  const auto line = [&](const char* name, const std::string& topic, const engine::IpcCounters& c) {
    out += std::string("ipc ") + name + " " + topic + " samples " +
           std::to_string(c.samples.load()) + " dropped " + std::to_string(c.dropped.load()) +
           " rejected " + std::to_string(c.rejected.load()) + "\n";
  };
  line("objects", objects_->topic(), objects_->counters());
  if (frames_) line("frames", frames_->topic(), frames_->counters());
  line("commands", commands_->topic(), commands_->counters());
  line("acks", acks_->topic(), acks_->counters());
  return out;
}

}  // namespace orthoflow::bridge
