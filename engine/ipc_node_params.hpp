#pragma once
/// @file
/// @brief The parameters of the IPC node kinds (docs/IPC.md), validated without RouDi: what
/// `ipc_publish` and `ipc_subscribe` check in both build modes before BuildMode::RUN connects.
#include <cstdint>
#include <string>

#include "engine/ipc_pubsub.hpp"
#include "engine/node.hpp"
#include "engine/params.hpp"

namespace orthoflow::engine {

/// @brief `ipc_publish`'s parameters.
struct IpcPublishParams {
  IpcTopic topic;
  std::string type;           ///< port type: frame or objects
  IpcPublisherConfig config;  ///< max_payload_bytes defaults to the pool's block bytes
  std::string roudi_config;   ///< RouDi TOML path; empty: RouDi's live pools (known once connected)
};

/// @brief `ipc_subscribe`'s parameters.
struct IpcSubscribeParams {
  IpcTopic topic;
  std::string type;  ///< port type: frame or objects
  IpcSubscriberConfig config;
  std::int64_t frames = 0;     ///< END after this many frames (0 = endless)
  std::int64_t idle_ms = 0;    ///< END after this long without data (0 = never)
  std::int64_t wait_ms = 100;  ///< longest wait inside produce() before an idle tombstone
};

/// @brief Validates `ipc_publish` parameters: known keys, choices and ranges, the topic
/// (BAD_TOPIC).
/// @return the message build_graph reports as BAD_PARAMETER. Start-up only; thread-safe.
[[nodiscard]] Result<IpcPublishParams, std::string> parse_ipc_publish_params(
    const ParamMap& params, const NodeContext& context);

/// @brief Validates `ipc_subscribe` parameters; `depth` is bounded by 256 minus the pool's blocks
/// (iceoryx lets a subscriber hold 256 chunks). @pre none; a missing pool is an error message.
/// Start-up only; thread-safe.
[[nodiscard]] Result<IpcSubscribeParams, std::string> parse_ipc_subscribe_params(
    const ParamMap& params, const NodeContext& context);

}  // namespace orthoflow::engine
