// Proves that the tabletop graph, after warm-up, performs no operator new per frame: sources,
// segmentation, tracking, GOOD, recognition (asking a learner that knows categories) and the
// session log, the objects output with an in-process consumer that asks over the learning channel.
// Teaching is excluded: a teach rebuilds the learner's snapshot (it allocates, once per lesson, by
// design; docs/TABLETOP.md). oneTBB's own task allocations do not go through operator new (see
// tests/engine/engine_alloc_test.cpp).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <thread>
#include <vector>

#include "tabletop_run.hpp"

#include "tests/support/counting_new.hpp"  // the one TU of this binary that replaces operator new

using orthoflow::test::g_allocations;
using orthoflow::test::g_counting;

namespace orthoflow::graphs {
namespace {

TEST(TabletopAllocations, SteadyStateAllocatesNothingPerFrame) {
  auto learning = test::in_memory_learning();
  // A learner that knows categories, so every ask walks real stored views.
  std::vector<float> views(3 * 675, 0.0F);
  for (std::size_t i = 0; i < views.size(); ++i) views[i] = static_cast<float>(i % 7) / 675.0F;
  ASSERT_TRUE(
      learning->teach("thing", std::span<const float>(views).first(2 * 675), 0, 0, {}).ok());
  ASSERT_TRUE(learning->teach("other", std::span<const float>(views).last(675), 0, 0, {}).ok());
  // a JSON sink too: its writer thread writes to /dev/null
  auto json = LineWriter::open("/dev/null");
  ASSERT_TRUE(json);
  SessionLog log(std::move(*json));
  ObjectsHub hub;  // an in-process consumer of the objects output, asking over the learning channel
  auto objects = hub.subscribe(16);
  auto client = learning->connect();
  const auto registry = make_tabletop_registry(*learning, log, &hub);
  // random scene with 5 objects, instructor off (teaching allocates by design)
  auto spec = test::tabletop_spec(
      {{"source", {{"objects", "5"}, {"frames", "60"}}}, {"recognise", {{"instructor", "0"}}}});
  auto graph = engine::build_graph(spec, registry);
  ASSERT_TRUE(graph) << engine::to_string(graph.error());
  engine::Engine engine(**graph, {2});
  // warm-up: 20 frames, then count over the remaining 40
  std::atomic<bool> stop{false};
  std::thread arm([&] {
    while (log.summary().frames < 20 && !stop.load())
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    g_counting.store(true);
  });
  std::uint64_t lists = 0, answers = 0;
  std::thread consumer([&] {
    engine::ObjectListPayload list;
    LearningAck ack;
    while (!stop.load()) {
      while (objects->poll(list)) {
        ++lists;
        if (list.count > 0) {
          LearningCommand ask;
          ask.kind = LearningCommand::Kind::ASK;
          ask.track_id = static_cast<std::uint32_t>(list.objects[0].track_id);
          (void)client->send(ask);
        }
      }
      while (client->poll(ack)) answers += ack.outcome == LearningAck::Outcome::ANSWERED ? 1 : 0;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  engine.run({});
  g_counting.store(false);
  stop.store(true);
  arm.join();
  consumer.join();
  EXPECT_GT(lists, 40U);
  EXPECT_GT(answers, 20U);
  EXPECT_EQ(log.summary().frames, 60U);
  EXPECT_GT(log.summary().object_views, 100U);
  EXPECT_GT(log.summary().recognitions, 100U);
  EXPECT_EQ(g_allocations.load(), 0U);
}

}  // namespace
}  // namespace orthoflow::graphs
