// Per-message overhead of the engine: the same generic nodes run (a) through the engine on oneTBB
// and (b) called directly in a loop, for a 4-node chain and a 10-object fan-out/join.
// Ratio = engine time per frame / direct time per frame (see bench/RESULTS.md).
#include <benchmark/benchmark.h>

#include <chrono>
#include <vector>

#include "engine/engine.hpp"
#include "engine/generic_nodes.hpp"
#include "engine/graph.hpp"
#include "engine/registry.hpp"

namespace {

using namespace orthoflow::engine;

constexpr int FRAMES = 20000;

const char* const CHAIN =
    "graph:\n  pool: {block_bytes: 128, blocks: 8}\nnodes:\n"
    "  - {name: src, kind: ticker, params: {frames: 20000, payload_bytes: 64}}\n"
    "  - {name: a, kind: busy, params: {add: 1}}\n"
    "  - {name: b, kind: busy, params: {add: 1, serial: 1}}\n"
    "  - {name: sink, kind: count}\n"
    "edges:\n  - src.out -> a.in\n  - a.out -> b.in\n  - b.out -> sink.in\n";

const char* const FANOUT =
    "graph:\n  pool: {block_bytes: 128, blocks: 8}\nnodes:\n"
    "  - {name: src, kind: ticker, params: {frames: 20000, payload_bytes: 64}}\n"
    "  - {name: split, kind: fanout, params: {objects: 10}}\n"
    "  - {name: obj, kind: busy, params: {type: object, add: 1}}\n"
    "  - {name: join, kind: join}\n"
    "  - {name: sink, kind: count}\n"
    "edges:\n  - src.out -> split.in\n  - split.out -> obj.in\n  - obj.out -> join.in\n  - "
    "join.out -> sink.in\n";

std::unique_ptr<Graph> build(const char* yaml) {
  static const NodeRegistry registry = [] {
    NodeRegistry r;
    add_generic_nodes(r);
    return r;
  }();
  auto spec_result = parse_graph(yaml, "bench");
  auto graph_result = build_graph(*spec_result, registry);
  return std::move(*graph_result);
}

void run_engine(benchmark::State& state, const char* yaml, std::int64_t messages_per_frame) {
  for (auto _ : state) {
    auto graph = build(yaml);
    Engine engine(*graph, {static_cast<int>(state.range(0))});
    const auto start = std::chrono::steady_clock::now();
    engine.run({});
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  state.SetItemsProcessed(state.iterations() * FRAMES);
  state.counters["ns_per_frame"] =
      benchmark::Counter(static_cast<double>(state.iterations() * FRAMES),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["messages_per_frame"] = static_cast<double>(messages_per_frame);
}

/// Calls the next node's process() directly: the "no runtime" baseline.
struct Direct final : Emitter {
  Node* next = nullptr;
  Emitter* next_out = nullptr;
  void emit(std::size_t /*port*/, const Message& message) noexcept override {
    next->process(message, *next_out);
  }
};

void run_direct(benchmark::State& state, const char* yaml) {
  for (auto _ : state) {
    auto graph = build(yaml);
    const auto order = graph->topo_order;  // source first
    std::vector<Direct> links(order.size());
    for (std::size_t i = 0; i + 1 < order.size(); ++i) {
      links[i].next = graph->nodes[order[i + 1]].get();
      links[i].next_out = &links[i + 1];
    }
    Node& source = *graph->nodes[order[0]];
    const auto start = std::chrono::steady_clock::now();
    for (std::uint64_t f = 0; f < FRAMES; ++f) {
      Message m;
      if (source.produce(m) == SourceStatus::END) break;
      m.frame_id = f;
      links[0].emit(0, m);
    }
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  state.SetItemsProcessed(state.iterations() * FRAMES);
  state.counters["ns_per_frame"] =
      benchmark::Counter(static_cast<double>(state.iterations() * FRAMES),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_Chain4_Engine(benchmark::State& state) { run_engine(state, CHAIN, 3); }
void BM_Chain4_Direct(benchmark::State& state) { run_direct(state, CHAIN); }
void BM_FanOut10Join_Engine(benchmark::State& state) { run_engine(state, FANOUT, 22); }
void BM_FanOut10Join_Direct(benchmark::State& state) { run_direct(state, FANOUT); }

BENCHMARK(BM_Chain4_Direct)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Chain4_Engine)->Arg(1)->Arg(2)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FanOut10Join_Direct)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FanOut10Join_Engine)->Arg(1)->Arg(2)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
