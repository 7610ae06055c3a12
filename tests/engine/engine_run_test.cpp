// Behaviour of a running graph: chain, thread counts, fan-out/join, ordering, latest-wins drops,
// deadlines, pool exhaustion at the source, and shutdown by request and by signal.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <ctime>
#include <thread>
#include <vector>

#include "engine/engine.hpp"
#include "engine/generic_nodes.hpp"
#include "graph_test_util.hpp"

namespace orthoflow::engine {
namespace {

using test::must_build;

std::string graph_text(const std::string& header, const std::string& nodes,
                       const std::string& edges) {
  return "graph:\n" + header + "nodes:\n" + nodes + "edges:\n" + edges;
}

CountSink& sink_of(const Engine& engine, const char* name = "sink") {
  auto* sink = dynamic_cast<CountSink*>(engine.node(name));
  EXPECT_NE(sink, nullptr);
  return *sink;
}

class ThreadCounts : public ::testing::TestWithParam<int> {};

TEST_P(ThreadCounts, ChainDeliversEveryFrameInOrderWithPayload) {
  auto graph = must_build(
      graph_text("  pool: {block_bytes: 64, blocks: 4}\n",
                 "  - {name: src, kind: ticker, params: {frames: 500, payload_bytes: 16}}\n"
                 "  - {name: a, kind: busy, params: {add: 1}}\n"
                 "  - {name: b, kind: busy, params: {add: 2, serial: 1}}\n"
                 "  - {name: sink, kind: count}\n",
                 "  - src.out -> a.in\n  - a.out -> b.in\n  - b.out -> sink.in\n"));
  ASSERT_TRUE(graph);
  Engine engine(*graph, {GetParam()});
  EXPECT_EQ(engine.run({}), StopReason::SOURCE_END);
  auto& sink = sink_of(engine);
  EXPECT_EQ(sink.received.load(), 500u);
  EXPECT_EQ(sink.skipped.load(), 0u);
  EXPECT_EQ(sink.payload_errors.load(), 0u);
  EXPECT_EQ(sink.value_sum.load(), 499 * 500 / 2 + 3 * 500);
  EXPECT_EQ(engine.stats().frames_done.load(), 500u);
  EXPECT_EQ(engine.stats().nodes[3].age.count(), 500u);
  EXPECT_EQ(graph->pool->free_count(), 4u);  // every block came back
}

INSTANTIATE_TEST_SUITE_P(Engine, ThreadCounts, ::testing::Values(1, 2, 4));

std::int64_t expected_join_sum(std::int64_t frames, std::int64_t objects, std::int64_t add) {
  std::int64_t sum = 0;
  for (std::int64_t f = 0; f < frames; ++f) {
    const std::int64_t c = f % (objects + 1);
    sum += c * f + c * (c - 1) / 2 + add * c;
  }
  return sum;
}

TEST(Engine, FanOutProcessesObjectsAndJoinsPerFrame) {
  auto graph = must_build(
      graph_text("  pool: {block_bytes: 64, blocks: 6}\n",
                 "  - {name: src, kind: ticker, params: {frames: 300, payload_bytes: 8}}\n"
                 "  - {name: split, kind: fanout, params: {objects: 5, vary: 1}}\n"
                 "  - {name: per_object, kind: busy, params: {type: object, add: 1000}}\n"
                 "  - {name: join, kind: join}\n"
                 "  - {name: sink, kind: count, ordered: true}\n",
                 "  - src.out -> split.in\n  - split.out -> per_object.in\n"
                 "  - per_object.out -> join.in\n  - join.out -> sink.in\n"));
  ASSERT_TRUE(graph);
  Engine engine(*graph, {2});
  engine.run({});
  auto& sink = sink_of(engine);
  EXPECT_EQ(sink.received.load(), 300u);
  EXPECT_EQ(sink.out_of_order.load(), 0u);
  EXPECT_EQ(sink.payload_errors.load(), 0u);
  EXPECT_EQ(sink.value_sum.load(), expected_join_sum(300, 5, 1000));
  // 300 frames with 0..5 objects: 50 empty frames pass through the per-object node untouched.
  EXPECT_EQ(engine.stats().nodes[2].processed.load(), 50u * (1 + 2 + 3 + 4 + 5));
  EXPECT_EQ(engine.stats().nodes[2].skipped.load(), 50u);
}

TEST(Engine, ObjectsOfOneFrameRunInParallel) {
  // Frames of 8 objects of 2 ms each on a 2-thread arena: the per-object node must be seen running
  // twice at once. That needs the host to actually give us two CPUs; on an oversubscribed CI box it
  // may not, so each attempt also measures process CPU time / wall time and the test is skipped
  // (not passed) only if no attempt ever got 1.5 CPUs' worth.
  std::uint32_t max_running = 0;
  double best_cpus = 0.0;
  for (int attempt = 0; attempt < 8 && max_running < 2; ++attempt) {
    auto graph = must_build(
        graph_text("  pool: {blocks: 2}\n",
                   "  - {name: src, kind: ticker, params: {frames: 4}}\n"
                   "  - {name: split, kind: fanout, params: {objects: 8}}\n"
                   "  - {name: work, kind: busy, params: {type: object, spin_us: 2000}}\n"
                   "  - {name: join, kind: join}\n  - {name: sink, kind: count}\n",
                   "  - src.out -> split.in\n  - split.out -> work.in\n"
                   "  - work.out -> join.in\n  - join.out -> sink.in\n"));
    ASSERT_TRUE(graph);
    Engine engine(*graph, {2});
    const std::clock_t cpu_start = std::clock();
    const auto wall_start = std::chrono::steady_clock::now();
    engine.run({});
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    const double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    best_cpus = std::max(best_cpus, cpu / wall);
    EXPECT_EQ(sink_of(engine).received.load(), 4u);
    max_running = engine.stats().nodes[2].max_running.load();
    EXPECT_EQ(engine.stats().nodes[4].max_running.load(), 1u);  // the stateful sink never overlaps
  }
  if (max_running < 2 && best_cpus < 1.5) {
    GTEST_SKIP() << "host never gave this process 1.5 CPUs (best " << best_cpus
                 << "): cannot observe parallelism";
  }
  EXPECT_GE(max_running, 2u);
}

TEST(Engine, SequencerRestoresFrameOrderAfterParallelStages) {
  // Frames with many objects finish later than empty ones, so the join emits out of order.
  const std::string nodes =
      "  - {name: src, kind: ticker, params: {frames: 200}}\n"
      "  - {name: split, kind: fanout, params: {objects: 6, vary: 1}}\n"
      "  - {name: work, kind: busy, params: {type: object, spin_us: 50}}\n"
      "  - {name: join, kind: join}\n";
  const std::string edges =
      "  - src.out -> split.in\n  - split.out -> work.in\n  - work.out -> join.in\n"
      "  - join.out -> sink.in\n";
  auto ordered = must_build(graph_text(
      "  pool: {blocks: 8}\n", nodes + "  - {name: sink, kind: count, ordered: true}\n", edges));
  auto unordered = must_build(
      graph_text("  pool: {blocks: 8}\n", nodes + "  - {name: sink, kind: count}\n", edges));
  ASSERT_TRUE(ordered && unordered);
  Engine with_sequencer(*ordered, {4});
  Engine without(*unordered, {4});
  with_sequencer.run({});
  without.run({});
  EXPECT_EQ(sink_of(with_sequencer).received.load(), 200u);
  EXPECT_EQ(sink_of(with_sequencer).out_of_order.load(), 0u);
  // Not asserted (depends on the scheduler), but shows the sequencer had work to do.
  RecordProperty("out_of_order_without_sequencer",
                 static_cast<int>(sink_of(without).out_of_order.load()));
}

std::string slow_graph(const char* policy) {
  return graph_text("  pool: {blocks: 8}\n",
                    std::string("  - {name: src, kind: ticker, params: {frames: 100}}\n"
                                "  - {name: slow, kind: busy, policy: ") +
                        policy +
                        ", params: {spin_us: 300, serial: 1}}\n"
                        "  - {name: sink, kind: count}\n",
                    "  - src.out -> slow.in\n  - slow.out -> sink.in\n");
}

TEST(Engine, LatestWinsDropsStaleFramesAndCountsEveryDrop) {
  // Drops need the source to run while the slow node works, i.e. a second thread actually joining
  // the arena; on a loaded 2-core CI box that can fail to happen in one short run, so retry a few
  // times. The accounting invariants are checked on every attempt.
  std::uint64_t drops = 0;
  for (int attempt = 0; attempt < 5 && drops == 0; ++attempt) {
    auto graph = must_build(slow_graph("latest"));
    ASSERT_TRUE(graph);
    Engine engine(*graph, {4});
    engine.run({});
    const auto& slow = engine.stats().nodes[1];
    auto& sink = sink_of(engine);
    drops = slow.dropped.load();
    EXPECT_EQ(slow.processed.load() + drops, 100u);
    EXPECT_EQ(sink.received.load(), 100u);  // dropped frames arrive as tombstones: nothing vanishes
    EXPECT_EQ(sink.skipped.load(), drops);
    EXPECT_EQ(engine.stats().total_drops(), drops);
    EXPECT_EQ(sink.last_frame.load(), 99u);
    EXPECT_EQ(sink.out_of_order.load(), 0u);
    EXPECT_EQ(slow.processed.load() > 0, true);
  }
  EXPECT_GT(drops, 0u);
}

TEST(Engine, QueuePolicyNeverDrops) {
  auto graph = must_build(slow_graph("queue"));
  ASSERT_TRUE(graph);
  Engine engine(*graph, {2});
  engine.run({});
  EXPECT_EQ(engine.stats().nodes[1].dropped.load(), 0u);
  EXPECT_EQ(sink_of(engine).skipped.load(), 0u);
  EXPECT_EQ(sink_of(engine).value_sum.load(), 99 * 100 / 2);
}

// Ten frames through a node that spins 3 ms on each; @p header: the graph's settings.
std::string ten_slow_frames(const std::string& header) {
  return graph_text(header,
                    "  - {name: src, kind: ticker, params: {frames: 10}}\n"
                    "  - {name: slow, kind: busy, params: {spin_us: 3000}}\n"
                    "  - {name: sink, kind: count}\n",
                    "  - src.out -> slow.in\n  - slow.out -> sink.in\n");
}

TEST(Engine, PeriodPacesTheSourceAndCountsDeadlineMisses) {
  auto graph = must_build(ten_slow_frames("  period_ms: 2\n  pool: {blocks: 2}\n"));
  ASSERT_TRUE(graph);
  Engine engine(*graph, {2});
  engine.run({});
  EXPECT_GE(engine.stats().elapsed_ns.load(), 9 * 2'000'000);
  EXPECT_EQ(engine.stats().nodes[1].deadline_misses.load(), 10u);
  EXPECT_EQ(engine.stats().deadline_misses.load(), 10u);
  EXPECT_GE(engine.stats().frame_latency.percentile(0.5), 3'000'000);
}

TEST(Engine, LatencyTraceHoldsEveryFramesExactLatencyUpToItsSize) {
  // 10 frames of at least 3 ms each into a trace of 7 (a trace shorter than the run) and one of 16
  // (longer): the first 7 (10) slots hold the frames' latencies, the rest stay untouched, and they
  // agree with the histogram (the same samples: the exact maximum, every value >= 3 ms).
  for (const std::size_t size : {std::size_t{7}, std::size_t{16}}) {
    auto graph = must_build(ten_slow_frames("  pool: {blocks: 2}\n"));
    ASSERT_TRUE(graph);
    Engine engine(*graph, {2});
    std::vector<std::int64_t> trace(size, -1);
    RunOptions options;
    options.latency_trace = trace;
    engine.run(options);
    const std::size_t written = std::min<std::size_t>(size, 10);
    ASSERT_EQ(engine.stats().frames_done.load(), 10u);
    for (std::size_t k = 0; k < size; ++k) {
      if (k < written) {
        EXPECT_GE(trace[k], 3'000'000) << k;
      } else {
        EXPECT_EQ(trace[k], -1) << k;
      }
    }
    const auto longest = *std::max_element(trace.begin(), trace.begin() + written);
    EXPECT_LE(longest, engine.stats().frame_latency.max());
    if (written == 10) { EXPECT_EQ(longest, engine.stats().frame_latency.max()); }
  }
}

TEST(Engine, PoolExhaustionAtTheSourceIsADrop) {
  auto graph = must_build(
      graph_text("  pool: {block_bytes: 64, blocks: 2}\n",
                 "  - {name: src, kind: ticker, params: {frames: 50, payload_bytes: 8}}\n"
                 "  - {name: slow, kind: busy, params: {spin_us: 200}}\n"
                 "  - {name: sink, kind: count}\n",
                 "  - src.out -> slow.in\n  - slow.out -> sink.in\n"));
  ASSERT_TRUE(graph);
  auto held = graph->pool->acquire("test", 8);  // leaves one block for two frames in flight
  ASSERT_TRUE(held);
  Engine engine(*graph, {2});
  engine.run({});
  EXPECT_GT(engine.stats().source_drops.load(), 0u);
  EXPECT_EQ(sink_of(engine).received.load(), 50u);
  EXPECT_EQ(sink_of(engine).skipped.load(), engine.stats().source_drops.load());
}

std::string endless_graph() {
  return graph_text("  pool: {block_bytes: 64, blocks: 4}\n",
                    "  - {name: src, kind: ticker, params: {payload_bytes: 8}}\n"
                    "  - {name: split, kind: fanout, params: {objects: 3}}\n"
                    "  - {name: work, kind: busy, params: {type: object, spin_us: 100}}\n"
                    "  - {name: join, kind: join}\n  - {name: sink, kind: count}\n",
                    "  - src.out -> split.in\n  - split.out -> work.in\n  - work.out -> join.in\n"
                    "  - join.out -> sink.in\n");
}

TEST(Engine, RequestStopDrainsInFlightFramesQuickly) {
  auto graph = must_build(endless_graph());
  ASSERT_TRUE(graph);
  Engine engine(*graph, {2});
  StopReason reason = StopReason::SOURCE_END;
  std::thread runner([&] { reason = engine.run({}); });
  while (engine.stats().frames_done.load() < 20)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const auto asked = std::chrono::steady_clock::now();
  engine.request_stop();
  runner.join();
  EXPECT_LT(std::chrono::steady_clock::now() - asked, std::chrono::milliseconds(500));
  EXPECT_EQ(reason, StopReason::STOP_REQUESTED);
  EXPECT_EQ(engine.stats().frames_in.load(), engine.stats().frames_done.load());
  EXPECT_EQ(sink_of(engine).received.load(), engine.stats().frames_done.load());
  EXPECT_EQ(graph->pool->free_count(), 4u);
}

std::atomic<bool> g_signalled{false};
extern "C" void on_signal(int) { g_signalled.store(true); }

TEST(Engine, SignalFlagStopsTheRun) {
  auto graph = must_build(endless_graph());
  ASSERT_TRUE(graph);
  Engine engine(*graph, {1});
  auto previous = std::signal(SIGTERM, on_signal);
  std::thread raiser([&] {
    while (engine.stats().frames_done.load() < 10)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::raise(SIGTERM);
  });
  EXPECT_EQ(engine.run({0, &g_signalled}), StopReason::STOP_REQUESTED);
  raiser.join();
  std::signal(SIGTERM, previous);
  EXPECT_EQ(engine.stats().frames_in.load(), engine.stats().frames_done.load());
}

TEST(Engine, FrameLimitStopsTheSource) {
  auto graph = must_build(endless_graph());
  ASSERT_TRUE(graph);
  Engine engine(*graph, {2});
  EXPECT_EQ(engine.run({25, nullptr}), StopReason::FRAME_LIMIT);
  EXPECT_EQ(engine.stats().frames_done.load(), 25u);
  EXPECT_EQ(engine.run({25, nullptr}), StopReason::FRAME_LIMIT);  // a second run is a no-op
  EXPECT_EQ(engine.stats().frames_done.load(), 25u);
}

}  // namespace
}  // namespace orthoflow::engine
