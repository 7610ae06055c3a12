// Maps a validated Graph onto a oneTBB flow graph (STYLE rule 7) and keeps per-frame accounting so
// that a frame's admission token comes back exactly when the last message of the frame has been
// consumed. The token ring plays the role of a limiter_node sized to the pool; unlike a limiter it
// also names the frame's slot, which must stay valid when frames complete out of order.
#include "engine/engine.hpp"

#include <thread>

#include "core/assert.hpp"
#include "engine/engine_impl.hpp"

namespace orthoflow::engine {

namespace {

using detail::now_ns;

}  // namespace

Engine::Impl::Impl(Graph& gr, const EngineConfig& config)
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

Engine::Impl::~Impl() {
  arena.execute([this] { g->wait_for_all(); });
  // Flow-graph nodes unregister from their graph when destroyed: tear them down before it.
  dispatch.reset();
  for (auto& rt : runtimes) {
    rt->sequencer.reset();
    rt->fn.reset();
  }
  g.reset();
}

void Engine::Impl::build_flow() {
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
