#pragma once
/// @file
/// @brief Engine::Impl (engine/engine.hpp), internal to engine/: the oneTBB flow graph built from
/// a validated Graph, the per-node runtimes and the per-frame accounting. engine.cpp builds and
/// tears it down and holds Engine's own functions; engine_frames.cpp holds the frame path
/// (admission and pacing, routing, running a node, completing a frame).
#include <oneapi/tbb/flow_graph.h>
#include <oneapi/tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "engine/engine.hpp"

namespace orthoflow::engine {

namespace flow = tbb::flow;

namespace detail {

/// @brief The steady clock in nanoseconds: frame stamps, service times and pacing. @pre none.
inline std::int64_t now_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct Target {
  std::size_t node = 0;
  std::uint32_t port = 0;
};

/// Messages still to be consumed for one frame in flight. Slot i belongs to admission token i, so
/// it is reused only after its frame completed, whatever order frames complete in.
struct FrameSlot {
  std::atomic<std::int64_t> pending{0};
  std::int64_t stamp_ns = 0;
};

}  // namespace detail

struct Engine::Impl {
  using Target = detail::Target;
  using FrameSlot = detail::FrameSlot;

  struct NodeRuntime {
    Node* node = nullptr;
    NodeStats* stats = nullptr;
    Policy policy = Policy::QUEUE;
    std::int64_t deadline_ns = 0;
    std::vector<std::vector<Target>> out;  // per output port
    std::atomic<std::uint64_t> newest{0};  // latest-wins: highest frame id sent to this node
    std::unique_ptr<flow::function_node<Message, flow::continue_msg>> fn;
    std::unique_ptr<flow::sequencer_node<Message>> sequencer;
    flow::receiver<Message>* entry = nullptr;
  };

  /// The engine-side Emitter handed to process(): routes a port to its edges and counts messages.
  struct Router final : Emitter {
    Impl* impl;
    NodeRuntime* from;
    const Message* in;
    Router(Impl* i, NodeRuntime* f, const Message* m) : impl(i), from(f), in(m) {}
    void emit(std::size_t port, const Message& message) noexcept override {
      Message out = message;  // frame identity is the engine's: it follows the input message
      out.frame_id = in->frame_id;
      out.stamp_ns = in->stamp_ns;
      out.slot = in->slot;
      impl->send(*from, port, out);
    }
  };

  Graph& graph;
  GraphStats stats;
  tbb::task_arena arena;
  std::unique_ptr<FrameSlot[]> slots;
  std::size_t slot_count;
  std::vector<std::unique_ptr<NodeRuntime>> runtimes;
  std::unique_ptr<flow::graph> g;
  std::unique_ptr<flow::function_node<Message, flow::continue_msg>> dispatch;
  std::atomic<bool> stop_requested{false};
  const std::atomic<bool>* external_stop = nullptr;
  std::uint64_t max_frames = 0;
  std::span<std::int64_t> latency_trace;  // RunOptions::latency_trace, indexed by frames_done
  std::uint64_t next_frame = 0;
  bool source_ended = false;  // touched only by the serial admission node
  std::atomic<std::int64_t> next_tick_ns{0};
  // Pacing without blocking an arena thread (with threads = 1 a sleeping task would stall the
  // whole graph): early tokens are parked here and a plain std::thread hands them back on time.
  std::mutex park_mutex;
  std::condition_variable park_cv;
  std::vector<std::uint32_t> parked;  // capacity max_in_flight, reserved at start-up
  bool pacer_exit = false;
  StopReason reason = StopReason::SOURCE_END;
  bool ran = false;

  /// @brief Builds the runtimes and the flow graph of @p gr inside the arena. engine.cpp.
  Impl(Graph& gr, const EngineConfig& config);
  /// @brief Waits for the flow graph, then destroys its nodes before it. engine.cpp.
  ~Impl();
  /// @brief One function_node per node but the source (behind a sequencer if ordered), and the
  /// serial admission node. engine.cpp.
  void build_flow();

  /// @brief True once request_stop() or the external stop flag asked. engine_frames.cpp.
  bool should_stop() const noexcept;
  /// @brief Turns @p token into the next frame, parks it until the next tick, or retires it.
  void admit(std::uint32_t token) noexcept;
  /// @brief Hands an early @p token to the pacer thread.
  void park(std::uint32_t token) noexcept;
  /// @brief The pacer thread's loop: gives parked tokens back to admission on time.
  void pace();
  /// @brief Sends @p message to every edge of output @p port of @p from, counting it pending.
  void send(NodeRuntime& from, std::size_t port, const Message& message) noexcept;
  /// @brief Sends a payload-less skipped copy of @p m on every output of @p rt.
  void forward_tombstone(NodeRuntime& rt, const Message& m) noexcept;
  /// @brief The flow-graph body of a node: process, pass through or drop @p m, then done().
  void run_node(NodeRuntime& rt, const Message& m) noexcept;
  /// @brief One message of the frame in @p slot_index consumed; the last returns the token.
  void done(std::uint32_t slot_index) noexcept;
};

}  // namespace orthoflow::engine
