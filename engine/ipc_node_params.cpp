#include "engine/ipc_node_params.hpp"

#include <algorithm>

#include "engine/ipc_nodes.hpp"

namespace orthoflow::engine {

namespace {

// ParamMap has typed getters for numbers and choices only; topics and paths are free text.
std::string text_param(const ParamMap& params, const std::string& key,
                       const std::string& fallback) {
  for (const auto& entry : params.entries()) {
    if (entry.key == key) return entry.value;
  }
  return fallback;
}

}  // namespace

Result<IpcPublishParams, std::string> parse_ipc_publish_params(const ParamMap& params,
                                                               const NodeContext& context) {
  if (auto ok = params.only({"topic", "type", "history", "lossless", "max_bytes", "roudi_config"});
      !ok) {
    return err(ok.error());
  }
  auto type_result = params.choice("type", "frame", {"frame", "objects"});
  if (!type_result) return err(type_result.error());
  IpcPublishParams parsed;
  parsed.type = *type_result;
  parsed.config.type = *ipc_payload_type(parsed.type);
  auto history = params.integer("history", 0, 0, 16);
  auto lossless = params.integer("lossless", 0, 0, 1);
  const auto block = static_cast<std::int64_t>(context.pool ? context.pool->block_bytes() : 4096);
  auto max_bytes = params.integer("max_bytes", block, 56, std::int64_t{1} << 30);
  if (!history) return err(history.error());
  if (!lossless) return err(lossless.error());
  if (!max_bytes) return err(max_bytes.error());
  parsed.config.history = static_cast<std::uint64_t>(*history);
  parsed.config.lossless = *lossless == 1;
  parsed.config.max_payload_bytes = static_cast<std::uint64_t>(*max_bytes);
  auto topic_result = parse_topic(text_param(params, "topic", ""));
  if (!topic_result) return err(to_string(topic_result.error()));
  parsed.topic = *topic_result;
  parsed.roudi_config = text_param(params, "roudi_config", "");
  return parsed;
}

Result<IpcSubscribeParams, std::string> parse_ipc_subscribe_params(const ParamMap& params,
                                                                   const NodeContext& context) {
  if (auto ok = params.only(
          {"topic", "type", "policy", "depth", "history", "frames", "idle_ms", "wait_ms"});
      !ok) {
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
  if (context.pool == nullptr || blocks > 255)
    return err(std::string("ipc_subscribe: needs a pool of 1..255 blocks"));
  auto topic_result = parse_topic(text_param(params, "topic", ""));
  if (!topic_result) return err(to_string(topic_result.error()));
  IpcSubscribeParams parsed;
  parsed.topic = *topic_result;
  parsed.type = *type_result;
  const IpcPolicy ipc_policy = *policy == "latest"  ? IpcPolicy::LATEST
                               : *policy == "queue" ? IpcPolicy::QUEUE
                                                    : IpcPolicy::LOSSLESS;
  parsed.config = {*ipc_payload_type(parsed.type), ipc_policy, static_cast<std::uint64_t>(*depth),
                   static_cast<std::uint64_t>(*history)};
  parsed.frames = *frames;
  parsed.idle_ms = *idle;
  parsed.wait_ms = *wait;
  return parsed;
}

}  // namespace orthoflow::engine
