// Maps a validated Graph onto a oneTBB flow graph (STYLE rule 7) and keeps per-frame accounting so
// that a frame's admission token comes back exactly when the last message of the frame has been
// consumed. The token ring plays the role of a limiter_node sized to the pool; unlike a limiter it
// also names the frame's slot, which must stay valid when frames complete out of order.
#include "engine/engine.hpp"

#include <oneapi/tbb/flow_graph.h>
#include <oneapi/tbb/task_arena.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "core/assert.hpp"

namespace orthoflow::engine {

namespace flow = tbb::flow;

namespace {

std::int64_t now_ns() noexcept {
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

}  // namespace

struct Engine::Impl {
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

  Impl(Graph& gr, const EngineConfig& config)
      : graph(gr),
        arena(config.threads > 0 ? config.threads : tbb::task_arena::automatic),
        slots(new FrameSlot[gr.max_in_flight]),
        slot_count(gr.max_in_flight) {
    stats.name = gr.spec.name;
    stats.period_ns = gr.spec.period_ns;
    for (std::size_t i = 0; i < gr.nodes.size(); ++i) {
      auto rt = std::make_unique<NodeRuntime>();
      rt->node = gr.nodes[i].get();
      rt->stats = &stats.nodes.emplace_back();
      rt->stats->name = gr.spec.nodes[i].name;
      rt->stats->sink = rt->node->outputs().empty();
      rt->stats->device = [node = rt->node](std::span<DeviceCounter> out) {
        return node->device_counters(out);
      };
      rt->stats->counter_group = rt->node->counter_group();
      rt->policy = gr.spec.nodes[i].policy;
      rt->deadline_ns =
          gr.spec.nodes[i].deadline_ns > 0 ? gr.spec.nodes[i].deadline_ns : gr.spec.period_ns;
      rt->out.resize(rt->node->outputs().size());
      runtimes.push_back(std::move(rt));
    }
    for (const auto& e : gr.edges) {
      runtimes[e.from_node]->out[e.from_port].push_back(
          {e.to_node, static_cast<std::uint32_t>(e.to_port)});
    }
    arena.execute([this] { build_flow(); });
  }

  ~Impl() {
    arena.execute([this] { g->wait_for_all(); });
    // Flow-graph nodes unregister from their graph when destroyed: tear them down before it.
    dispatch.reset();
    for (auto& rt : runtimes) {
      rt->sequencer.reset();
      rt->fn.reset();
    }
    g.reset();
  }

  void build_flow() {
    g = std::make_unique<flow::graph>();
    for (std::size_t i = 0; i < runtimes.size(); ++i) {
      if (i == graph.source) continue;
      NodeRuntime* rt = runtimes[i].get();
      const std::size_t concurrency = rt->node->stateful() ? flow::serial : flow::unlimited;
      rt->fn = std::make_unique<flow::function_node<Message, flow::continue_msg>>(
          *g, concurrency, [this, rt](const Message& m) {
            run_node(*rt, m);
            return flow::continue_msg();
          });
      rt->entry = rt->fn.get();
      if (graph.spec.nodes[i].ordered) {
        rt->sequencer = std::make_unique<flow::sequencer_node<Message>>(
            *g, [](const Message& m) { return static_cast<std::size_t>(m.frame_id); });
        flow::make_edge(*rt->sequencer, *rt->fn);
        rt->entry = rt->sequencer.get();
      }
    }
    dispatch = std::make_unique<flow::function_node<Message, flow::continue_msg>>(
        *g, flow::serial, [this](const Message& token) {
          admit(token.slot);
          return flow::continue_msg();
        });
  }

  bool should_stop() const noexcept {
    return stop_requested.load(std::memory_order_relaxed) ||
           (external_stop != nullptr && external_stop->load(std::memory_order_relaxed));
  }

  // Admission (the limiter): exactly max_in_flight tokens circulate. run() puts them all into
  // this serial node; each completed frame puts its token back (done()). A token either becomes
  // the next frame (paced at the graph period) or is retired when the run is stopping, so frames in
  // flight never exceed the pool's blocks and the source never takes a block it cannot use yet.
  void admit(std::uint32_t token) noexcept {
    if (max_frames > 0 && next_frame >= max_frames && reason == StopReason::SOURCE_END) {
      reason = StopReason::FRAME_LIMIT;
    }
    if (reason == StopReason::SOURCE_END && should_stop()) reason = StopReason::STOP_REQUESTED;
    if (reason != StopReason::SOURCE_END || source_ended) return;  // token retired
    if (graph.spec.period_ns > 0 && now_ns() < next_tick_ns.load(std::memory_order_relaxed)) {
      park(token);  // too early: the pacer thread gives it back at the next tick
      return;
    }
    Message m;
    const std::int64_t start = now_ns();
    if (graph.nodes[graph.source]->produce(m) == SourceStatus::END) {
      source_ended = true;
      return;
    }
    next_tick_ns.store(
        std::max(next_tick_ns.load(std::memory_order_relaxed) + graph.spec.period_ns, now_ns()),
        std::memory_order_relaxed);
    NodeStats& source_stats = *runtimes[graph.source]->stats;
    source_stats.processed.fetch_add(1, std::memory_order_relaxed);
    source_stats.service.record(now_ns() - start);
    m.frame_id = next_frame++;
    m.stamp_ns = now_ns();
    m.slot = token;
    FrameSlot& slot = slots[token];
    slot.stamp_ns = m.stamp_ns;
    slot.pending.store(1, std::memory_order_relaxed);  // the dispatcher's own hold, released below
    stats.frames_in.fetch_add(1, std::memory_order_relaxed);
    if (m.skipped) stats.source_drops.fetch_add(1, std::memory_order_relaxed);
    NodeRuntime& source = *runtimes[graph.source];
    for (std::size_t port = 0; port < source.out.size(); ++port) send(source, port, m);
    m.payload.reset();
    done(m.slot);
  }

  void park(std::uint32_t token) noexcept {
    g->reserve_wait();  // keeps wait_for_all() from returning while the token is parked
    {
      const std::lock_guard<std::mutex> lock(park_mutex);
      parked.push_back(token);  // never reallocates: at most max_in_flight tokens exist
    }
    park_cv.notify_one();
  }

  void pace() {
    std::unique_lock<std::mutex> lock(park_mutex);
    while (true) {
      park_cv.wait(lock, [this] { return pacer_exit || !parked.empty(); });
      if (parked.empty()) return;
      Message token;
      token.slot = parked.back();
      parked.pop_back();
      lock.unlock();
      // Sleep in short slices so a stop request is seen within ~2 ms.
      while (now_ns() < next_tick_ns.load(std::memory_order_relaxed) && !should_stop()) {
        const std::int64_t left_us =
            (next_tick_ns.load(std::memory_order_relaxed) - now_ns()) / 1000 + 1;
        std::this_thread::sleep_for(
            std::chrono::microseconds(std::min<std::int64_t>(2000, left_us)));
      }
      dispatch->try_put(token);
      g->release_wait();
      lock.lock();
    }
  }

  void send(NodeRuntime& from, std::size_t port, const Message& message) noexcept {
    for (const Target& t : from.out[port]) {
      NodeRuntime& to = *runtimes[t.node];
      slots[message.slot].pending.fetch_add(1, std::memory_order_relaxed);
      if (to.policy == Policy::LATEST) {
        std::uint64_t seen = to.newest.load(std::memory_order_relaxed);
        while (message.frame_id > seen &&
               !to.newest.compare_exchange_weak(seen, message.frame_id)) {}
      }
      Message copy = message;
      copy.port = t.port;
      to.entry->try_put(copy);
    }
  }

  void forward_tombstone(NodeRuntime& rt, const Message& m) noexcept {
    Message tomb = m;
    tomb.skipped = true;
    tomb.payload.reset();
    for (std::size_t port = 0; port < rt.out.size(); ++port) send(rt, port, tomb);
  }

  void run_node(NodeRuntime& rt, const Message& m) noexcept {
    const std::int64_t start = now_ns();
    if ((m.skipped || m.object_count == 0) && !rt.node->wants_skipped()) {
      // Tombstones and empty frames (no objects) flow through untouched so joins and sequencers
      // downstream still see exactly one message per frame.
      rt.stats->skipped.fetch_add(1, std::memory_order_relaxed);
      for (std::size_t port = 0; port < rt.out.size(); ++port) send(rt, port, m);
    } else if (rt.policy == Policy::LATEST &&
               m.frame_id < rt.newest.load(std::memory_order_relaxed)) {
      rt.stats->dropped.fetch_add(1, std::memory_order_relaxed);  // a newer frame is already queued
      forward_tombstone(rt, m);
    } else {
      Router router(this, &rt, &m);
      // Concurrency gauge: shows per-object work really runs in parallel (telemetry, tests).
      const std::uint32_t running = rt.stats->running.fetch_add(1, std::memory_order_relaxed) + 1;
      std::uint32_t seen = rt.stats->max_running.load(std::memory_order_relaxed);
      while (running > seen && !rt.stats->max_running.compare_exchange_weak(seen, running)) {}
      rt.node->process(m, router);
      rt.stats->running.fetch_sub(1, std::memory_order_relaxed);
      const std::int64_t end = now_ns();
      rt.stats->processed.fetch_add(1, std::memory_order_relaxed);
      rt.stats->service.record(end - start);
      if (rt.deadline_ns > 0 && end - start > rt.deadline_ns)
        rt.stats->deadline_misses.fetch_add(1);
      if (rt.stats->sink) rt.stats->age.record(end - m.stamp_ns);
    }
    // TBB hands the body a reference to its own non-const copy (held by the task or buffer);
    // releasing the block here, before the frame can complete, guarantees admission never
    // admits a frame while the previous frame's block is still held by a finishing task.
    const_cast<Message&>(m).payload.reset();
    done(m.slot);
  }

  // Called once per consumed message; the call that takes the count to zero completes the frame.
  void done(std::uint32_t slot_index) noexcept {
    FrameSlot& slot = slots[slot_index];
    if (slot.pending.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
    const std::int64_t latency = now_ns() - slot.stamp_ns;
    stats.frame_latency.record(latency);
    if (graph.spec.period_ns > 0 && latency > graph.spec.period_ns)
      stats.deadline_misses.fetch_add(1);
    const std::uint64_t k = stats.frames_done.fetch_add(1, std::memory_order_relaxed);
    if (k < latency_trace.size()) latency_trace[k] = latency;
    Message token;
    token.slot = slot_index;
    dispatch->try_put(token);  // hand the token back: the next frame may start
  }
};

Engine::Engine(Graph& graph, const EngineConfig& config) {
  OF_ENFORCE(graph.mode == BuildMode::RUN,
             "Engine: a graph built with BuildMode::CHECK cannot run");
  impl_ = std::make_unique<Impl>(graph, config);
}

Engine::~Engine() = default;

StopReason Engine::run(const RunOptions& options) {
  if (impl_->ran) return impl_->reason;
  impl_->ran = true;
  impl_->external_stop = options.stop;
  impl_->max_frames = options.max_frames;
  impl_->latency_trace = options.latency_trace;
  const std::int64_t start = now_ns();
  impl_->next_tick_ns.store(start);
  impl_->parked.reserve(impl_->slot_count);
  std::thread pacer;
  if (impl_->graph.spec.period_ns > 0) pacer = std::thread([this] { impl_->pace(); });
  impl_->arena.execute([this] {
    for (std::size_t i = 0; i < impl_->slot_count; ++i) {
      Message token;
      token.slot = static_cast<std::uint32_t>(i);
      impl_->dispatch->try_put(token);
    }
    impl_->g->wait_for_all();
  });
  if (pacer.joinable()) {
    {
      const std::lock_guard<std::mutex> lock(impl_->park_mutex);
      impl_->pacer_exit = true;
    }
    impl_->park_cv.notify_one();
    pacer.join();
  }
  impl_->stats.elapsed_ns.store(now_ns() - start);
  return impl_->reason;
}

void Engine::request_stop() noexcept {
  impl_->stop_requested.store(true, std::memory_order_relaxed);
}

const GraphStats& Engine::stats() const noexcept { return impl_->stats; }

Node* Engine::node(std::string_view name) const noexcept {
  for (std::size_t i = 0; i < impl_->graph.spec.nodes.size(); ++i) {
    if (impl_->graph.spec.nodes[i].name == name) return impl_->graph.nodes[i].get();
  }
  return nullptr;
}

}  // namespace orthoflow::engine
