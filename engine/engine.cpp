// Maps a validated Graph onto a oneTBB flow graph (STYLE rule 7) and keeps per-frame accounting so
// the limiter is released exactly when the last message of a frame has been consumed.
#include "engine/engine.hpp"

#include <oneapi/tbb/flow_graph.h>
#include <oneapi/tbb/task_arena.h>

#include <chrono>
#include <thread>
#include <vector>

namespace orthoflow::engine {

namespace flow = tbb::flow;

namespace {

std::int64_t now_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct Target {
  std::size_t node = 0;
  std::uint32_t port = 0;
};

/// Messages still to be consumed for one frame; the slot is reused by frame_id + max_in_flight,
/// which the limiter only admits after this frame completed.
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
    Router(Impl* i, NodeRuntime* f) : impl(i), from(f) {}
    void emit(std::size_t port, const Message& message) noexcept override { impl->send(*from, port, message); }
  };

  Graph& graph;
  GraphStats stats;
  tbb::task_arena arena;
  std::unique_ptr<FrameSlot[]> slots;
  std::size_t slot_count;
  std::vector<std::unique_ptr<NodeRuntime>> runtimes;
  std::unique_ptr<flow::graph> g;
  std::unique_ptr<flow::input_node<Message>> input;
  std::unique_ptr<flow::limiter_node<Message>> limiter;
  std::unique_ptr<flow::function_node<Message, flow::continue_msg>> dispatch;
  std::atomic<bool> stop_requested{false};
  const std::atomic<bool>* external_stop = nullptr;
  std::uint64_t max_frames = 0;
  std::uint64_t next_frame = 0;
  std::int64_t next_tick_ns = 0;
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
      rt->policy = gr.spec.nodes[i].policy;
      rt->deadline_ns = gr.spec.nodes[i].deadline_ns > 0 ? gr.spec.nodes[i].deadline_ns : gr.spec.period_ns;
      rt->out.resize(rt->node->outputs().size());
      runtimes.push_back(std::move(rt));
    }
    for (const auto& e : gr.edges) {
      runtimes[e.from_node]->out[e.from_port].push_back({e.to_node, static_cast<std::uint32_t>(e.to_port)});
    }
    arena.execute([this] { build_flow(); });
  }

  ~Impl() {
    arena.execute([this] { g->wait_for_all(); });
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
    input = std::make_unique<flow::input_node<Message>>(*g, [this](tbb::flow_control& fc) { return produce(fc); });
    limiter = std::make_unique<flow::limiter_node<Message>>(*g, slot_count);
    dispatch = std::make_unique<flow::function_node<Message, flow::continue_msg>>(
        *g, flow::serial, [this](const Message& m) {
          start_frame(m);
          return flow::continue_msg();
        });
    flow::make_edge(*input, *limiter);
    flow::make_edge(*limiter, *dispatch);
  }

  bool should_stop() const noexcept {
    return stop_requested.load(std::memory_order_relaxed) ||
           (external_stop != nullptr && external_stop->load(std::memory_order_relaxed));
  }

  // Paces the source at the graph period; sleeps in short slices so a stop is seen within ~2 ms.
  Message produce(tbb::flow_control& fc) {
    Message m;
    if (max_frames > 0 && next_frame >= max_frames) reason = StopReason::FRAME_LIMIT;
    while (reason == StopReason::SOURCE_END && graph.spec.period_ns > 0 && now_ns() < next_tick_ns &&
           !should_stop()) {
      std::this_thread::sleep_for(std::chrono::microseconds(std::min<std::int64_t>(
          2000, (next_tick_ns - now_ns()) / 1000 + 1)));
    }
    if (should_stop()) reason = StopReason::STOP_REQUESTED;
    const std::int64_t start = now_ns();
    if (reason != StopReason::SOURCE_END || graph.nodes[graph.source]->produce(m) == SourceStatus::END) {
      fc.stop();
      return {};
    }
    NodeStats& source_stats = *runtimes[graph.source]->stats;
    source_stats.processed.fetch_add(1, std::memory_order_relaxed);
    source_stats.service.record(now_ns() - start);
    next_tick_ns = std::max(next_tick_ns + graph.spec.period_ns, now_ns());
    m.frame_id = next_frame++;
    m.stamp_ns = now_ns();
    return m;
  }

  void start_frame(const Message& m) noexcept {
    FrameSlot& slot = slots[m.frame_id % slot_count];
    slot.stamp_ns = m.stamp_ns;
    slot.pending.store(1, std::memory_order_relaxed);  // the dispatcher's own hold, released below
    stats.frames_in.fetch_add(1, std::memory_order_relaxed);
    if (m.skipped) stats.source_drops.fetch_add(1, std::memory_order_relaxed);
    NodeRuntime& source = *runtimes[graph.source];
    for (std::size_t port = 0; port < source.out.size(); ++port) send(source, port, m);
    done(m.frame_id);
  }

  void send(NodeRuntime& from, std::size_t port, const Message& message) noexcept {
    for (const Target& t : from.out[port]) {
      NodeRuntime& to = *runtimes[t.node];
      slots[message.frame_id % slot_count].pending.fetch_add(1, std::memory_order_relaxed);
      if (to.policy == Policy::LATEST) {
        std::uint64_t seen = to.newest.load(std::memory_order_relaxed);
        while (message.frame_id > seen && !to.newest.compare_exchange_weak(seen, message.frame_id)) {
        }
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
    if (m.skipped && !rt.node->wants_skipped()) {
      rt.stats->skipped.fetch_add(1, std::memory_order_relaxed);
      forward_tombstone(rt, m);
    } else if (rt.policy == Policy::LATEST && m.frame_id < rt.newest.load(std::memory_order_relaxed)) {
      rt.stats->dropped.fetch_add(1, std::memory_order_relaxed);  // a newer frame is already queued
      forward_tombstone(rt, m);
    } else {
      Router router(this, &rt);
      rt.node->process(m, router);
      const std::int64_t end = now_ns();
      rt.stats->processed.fetch_add(1, std::memory_order_relaxed);
      rt.stats->service.record(end - start);
      if (rt.deadline_ns > 0 && end - start > rt.deadline_ns) rt.stats->deadline_misses.fetch_add(1);
      if (rt.stats->sink) rt.stats->age.record(end - m.stamp_ns);
    }
    done(m.frame_id);
  }

  // Called once per consumed message; the call that takes the count to zero completes the frame.
  void done(std::uint64_t frame_id) noexcept {
    FrameSlot& slot = slots[frame_id % slot_count];
    if (slot.pending.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
    const std::int64_t latency = now_ns() - slot.stamp_ns;
    stats.frame_latency.record(latency);
    if (graph.spec.period_ns > 0 && latency > graph.spec.period_ns) stats.deadline_misses.fetch_add(1);
    stats.frames_done.fetch_add(1, std::memory_order_relaxed);
    limiter->decrementer().try_put(flow::continue_msg());
  }
};

Engine::Engine(Graph& graph, const EngineConfig& config) : impl_(std::make_unique<Impl>(graph, config)) {}

Engine::~Engine() = default;

StopReason Engine::run(const RunOptions& options) {
  if (impl_->ran) return impl_->reason;
  impl_->ran = true;
  impl_->external_stop = options.stop;
  impl_->max_frames = options.max_frames;
  const std::int64_t start = now_ns();
  impl_->next_tick_ns = start;
  impl_->arena.execute([this] {
    impl_->input->activate();
    impl_->g->wait_for_all();
  });
  impl_->stats.elapsed_ns.store(now_ns() - start);
  return impl_->reason;
}

void Engine::request_stop() noexcept { impl_->stop_requested.store(true, std::memory_order_relaxed); }

const GraphStats& Engine::stats() const noexcept { return impl_->stats; }

Node* Engine::node(std::string_view name) const noexcept {
  for (std::size_t i = 0; i < impl_->graph.spec.nodes.size(); ++i) {
    if (impl_->graph.spec.nodes[i].name == name) return impl_->graph.nodes[i].get();
  }
  return nullptr;
}

}  // namespace orthoflow::engine
