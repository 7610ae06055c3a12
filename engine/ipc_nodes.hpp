#pragma once
/// @file
/// @brief Graph node kinds that cross process boundaries through iceoryx:
/// - `ipc_publish` (sink): publishes each input block's payload [0, payload_bytes) on `topic`
///   (one copy, block -> chunk; sources that can write in place use IpcPublisher::loan()).
/// - `ipc_subscribe` (source): hands each received chunk downstream without copying: the frame's
///   pool block holds a FrameRef (ipc_frame_ref.hpp) to the chunk, which the node keeps until the
///   block is released by every reader.
/// Built for running (BuildMode::RUN), both register the process with RouDi (an error if none
/// runs); built with BuildMode::CHECK they validate every parameter (ipc_node_params.hpp) and
/// connect to nothing.
#include <string>

#include "engine/ipc_pubsub.hpp"
#include "engine/registry.hpp"

namespace orthoflow::engine {

/// @brief What every IPC node kind exposes for telemetry: its topic and its counters.
class IpcNode : public Node {
 public:
  /// @brief `service/instance/event`.
  [[nodiscard]] virtual const std::string& topic() const noexcept = 0;
  /// @brief Samples, drops (sequence gaps and latest-wins replacements), rejected, loan failures.
  /// Readable from any thread while the graph runs.
  [[nodiscard]] virtual const IpcCounters& ipc_counters() const noexcept = 0;
};

/// @brief Payload type of a port type name: "frame" (FrameHeader) or "objects" (ObjectListPayload).
/// @return an error message for any other name.
[[nodiscard]] Result<IpcPayloadType, std::string> ipc_payload_type(const std::string& port_type);

/// @brief Registers `ipc_publish` and `ipc_subscribe` (parameters in docs/IPC.md).
/// @pre Neither kind registered yet. Start-up only.
void add_ipc_nodes(NodeRegistry& registry);

}  // namespace orthoflow::engine
