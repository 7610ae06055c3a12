#pragma once
/// @file
/// @brief Node: the unit of computation in a graph, with typed input and output ports.
#include <span>
#include <string>
#include <string_view>

#include "engine/message.hpp"
#include "engine/telemetry.hpp"
#include "memory_pool/block_pool.hpp"

namespace orthoflow::engine {

struct GraphSpec;

/// @brief One port of a node kind. Two ports connect only if their `type` strings are equal.
struct PortSpec {
  std::string name;
  std::string type;
  bool required = true;  ///< an input that must have at least one incoming edge
};

/// @brief What a graph is built for. RUN: nodes are ready to run, so kinds that talk to another
/// process or a device connect in their factories (and fail there if it is absent). CHECK: every
/// parameter is validated exactly as for RUN, but nothing outside this process is touched; the
/// nodes have their ports and cannot run (`graph check`, `graph dot`).
enum class BuildMode { RUN, CHECK };

/// @brief What a node can use while it runs; owned by the engine and alive as long as the node.
struct NodeContext {
  std::string_view name;                   ///< the node's instance name (for pool error messages)
  memory_pool::BlockPool* pool = nullptr;  ///< the graph's frame pool
  std::size_t max_in_flight = 1;           ///< frames that can be in flight at once (limiter size)
  BuildMode mode = BuildMode::RUN;         ///< CHECK: validate only, connect to nothing
  /// The whole graph, for kinds whose layout depends on another node's parameters (the tabletop
  /// frame block's descriptor room follows the describe node's). Null when a node is made alone.
  const GraphSpec* graph = nullptr;
};

/// @brief Where a node puts its results during process(). Implemented by the engine.
class Emitter {
 public:
  /// @brief Sends `message` out of output port `port` to every connected input. Never allocates.
  virtual void emit(std::size_t port, const Message& message) noexcept = 0;

 protected:
  ~Emitter() = default;
};

/// @brief Result of asking a source for its next frame.
enum class SourceStatus { FRAME, END };

/// @brief Base class of every node kind. A node with no inputs is a source.
/// @note Thread safety: if stateful() is false the engine may call process() concurrently from
/// several threads, so the node must not mutate members there; stateful nodes get one message at
/// a time. Nothing on the frame path may throw.
class Node {
 public:
  virtual ~Node() = default;
  [[nodiscard]] virtual std::span<const PortSpec> inputs() const noexcept = 0;
  [[nodiscard]] virtual std::span<const PortSpec> outputs() const noexcept = 0;
  /// @brief True if process() mutates state: the engine then serializes it.
  [[nodiscard]] virtual bool stateful() const noexcept = 0;
  /// @brief True if the node wants tombstones (skipped messages) delivered, e.g. to count them in a
  /// join. Otherwise the engine forwards one tombstone per output port on its behalf.
  [[nodiscard]] virtual bool wants_skipped() const noexcept { return false; }
  /// @brief Handles one message arriving on input `in.port`.
  virtual void process(const Message& in, Emitter& out) noexcept = 0;
  /// @brief Sources only: fills the next frame's payload/value (the engine sets id and stamp).
  /// @pre inputs().empty(). Called serially.
  virtual SourceStatus produce(Message& /*out*/) noexcept { return SourceStatus::END; }
  /// @brief Nodes in front of a device (a camera) report its counters into @p out (at most
  /// out.size()); the telemetry shows them under the node. @return how many. @note Any thread, at
  /// any time while the graph lives: read snapshots, never block.
  [[nodiscard]] virtual std::size_t device_counters(std::span<DeviceCounter> out) const noexcept {
    (void)out;
    return 0;
  }
  /// @brief What the counters of device_counters() are about, as the telemetry names them: "device"
  /// for a camera's own account; a stage reports its own (the table stage: "plane"). Static
  /// storage.
  [[nodiscard]] virtual const char* counter_group() const noexcept { return "device"; }
};

}  // namespace orthoflow::engine
