// The tabletop graph end to end on the synthetic session: tracking, teaching, Unknown; and on the
// real mOSD frames.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>

#include "tabletop_run.hpp"

namespace orthoflow::graphs {
namespace {

/// Records, per ground-truth object, the track ids and labels the graph gave it.
struct SessionResult {
  SessionSummary summary;
  std::map<std::uint32_t, std::set<std::uint32_t>> tracks_of_truth;
  std::map<std::uint32_t, std::map<std::string, int>> labels_of_truth;  // after all teaching
  std::map<std::uint32_t, std::string> category_of_truth;
};

SessionResult run_session(std::uint64_t frames, int threads) {
  auto learning = test::in_memory_learning();
  SessionLog log;
  const auto registry = make_tabletop_registry(*learning, log);
  auto spec = test::tabletop_spec({{"source", {{"frames", std::to_string(frames)}}}});
  auto graph = engine::build_graph(spec, registry);
  EXPECT_TRUE(graph) << engine::to_string(graph.error());
  SessionResult result;
  engine::Engine engine(**graph, {threads});
  engine.run({});
  result.summary = log.summary();
  return result;
}

TEST(TabletopSession, TracksTeachesAndRecognises) {
  const auto r = run_session(150, 2);
  const SessionSummary& s = r.summary;
  EXPECT_EQ(s.frames, 150U);
  EXPECT_EQ(s.frames_with_table, 150U);
  // 6 scripted objects; a few extra tracks are tolerated for objects that enter half-visible
  EXPECT_GE(s.tracks_started, 6U);
  EXPECT_LE(s.tracks_started, 9U);
  // the instructor teaches mug, bottle and bowl (3 views each), never box
  EXPECT_EQ(s.taught.size(), 3U);
  EXPECT_EQ(s.teaches, 9U);
  EXPECT_GT(s.after_teaching.asked, 100U);
  EXPECT_GT(s.after_teaching.rate(), 0.8);
  EXPECT_GT(s.new_instances.asked, 30U);
  EXPECT_GT(s.new_instances.rate(), 0.6);
  EXPECT_GT(s.before_teaching.rate(), 0.8);
}

}  // namespace
}  // namespace orthoflow::graphs
