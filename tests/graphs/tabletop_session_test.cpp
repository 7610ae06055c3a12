// The tabletop graph end to end: the synthetic session (tracking, teaching, Unknown, determinism
// across thread counts), outside teach events, and the real mOSD frames.
#include <gtest/gtest.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include "tabletop_run.hpp"

namespace orthoflow::graphs {
namespace {

struct SessionRun {
  SessionSummary summary;
  std::vector<nlohmann::json> frames;  // the JSON lines
};

SessionRun run_graph(const test::Overrides& overrides, int threads, LearningService& learning) {
  // One file per process and run: ctest runs these tests in parallel processes.
  static int runs = 0;
  const auto path =
      std::filesystem::temp_directory_path() /
      ("orthoflow_session_" + std::to_string(::getpid()) + "_" + std::to_string(runs++) + ".jsonl");
  SessionRun result;
  {
    auto json = LineWriter::open(path.string());
    EXPECT_TRUE(json);
    SessionLog log(std::move(*json));
    const auto registry = make_tabletop_registry(learning, log);
    auto graph = engine::build_graph(test::tabletop_spec(overrides), registry);
    EXPECT_TRUE(graph) << engine::to_string(graph.error());
    engine::Engine engine(**graph, {threads});
    engine.run({});
    result.summary = log.summary();
  }  // the writer flushes and closes here
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
    result.frames.push_back(nlohmann::json::parse(line));
  std::filesystem::remove(path);
  return result;
}

const test::Overrides SESSION{{"source", {{"frames", "90"}}}};

TEST(TabletopSession, TracksTeachesAndRecognises) {
  auto learning = test::in_memory_learning();
  const auto r = run_graph(SESSION, 2, *learning);
  const SessionSummary& s = r.summary;
  ASSERT_EQ(s.frames, 90U);
  ASSERT_EQ(r.frames.size(), 90U);
  EXPECT_EQ(s.frames_with_table, 90U);
  // Tracking: every scripted object keeps one track id while it stays (the mug slides 5 cm/s).
  std::map<std::string, std::set<int>> tracks_of;  // truth category + phase -> track ids
  for (const auto& f : r.frames) {
    for (const auto& o : f["objects"]) {
      const std::string phase =
          f["frame"].get<int>() < 36 ? "1" : "2";  // phase 1 ends at 40% of 90
      const std::string truth = o["truth"];
      tracks_of[truth == "bowl" ? truth : truth + phase].insert(o["track"].get<int>());
    }
  }
  EXPECT_EQ(tracks_of.size(), 6U);
  for (const auto& [object, ids] : tracks_of) EXPECT_EQ(ids.size(), 1U) << object;
  EXPECT_EQ(s.tracks_started, 6U);
  // Teaching: the instructor teaches mug, bottle and bowl (3 views each), never the plate.
  EXPECT_EQ(s.taught, (std::vector<std::string>{"bowl", "bottle", "mug"}));
  EXPECT_EQ(s.teaches, 9U);
  // A taught category is recognised on a new instance; the never-taught plate is Unknown.
  EXPECT_GT(s.new_instances.asked, 60U);
  EXPECT_GT(s.new_instances.rate(), 0.9);
  EXPECT_GT(s.after_teaching.rate(), 0.9);
  EXPECT_GT(s.before_teaching.asked, 50U);
  EXPECT_GT(s.before_teaching.rate(), 0.95);
  int plates = 0;
  for (const auto& f : r.frames) {
    for (const auto& o : f["objects"]) {
      if (o["truth"] != "plate") continue;
      ++plates;
      EXPECT_TRUE(o["unknown"].get<bool>()) << f["frame"];
    }
  }
  EXPECT_GE(plates, 45);  // the plate is on the table for the last 50 frames
}

TEST(TabletopSession, SameOutputWhateverTheThreadCount) {
  auto one = test::in_memory_learning();
  auto two = test::in_memory_learning();
  const test::Overrides shorter{{"source", {{"frames", "30"}}}};
  const auto a = run_graph(shorter, 1, *one);
  const auto b = run_graph(shorter, 2, *two);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    auto fa = a.frames[i], fb = b.frames[i];
    EXPECT_EQ(fa, fb) << "frame " << i;
  }
}

TEST(TabletopSession, OutsideTeachEventTeachesTheTrackedObject) {
  auto learning = test::in_memory_learning();
  auto client = learning->connect();
  ASSERT_TRUE(client);
  LearningCommand teach;
  teach.kind = LearningCommand::Kind::TEACH;
  teach.track_id = 1;  // the first object the tracker sees
  teach.label.assign("my-thing");
  const std::uint64_t sequence = client->send(teach);
  ASSERT_NE(sequence, 0U);
  const auto r = run_graph({{"source", {{"frames", "10"}}}, {"recognise", {{"instructor", "0"}}}},
                           2, *learning);
  EXPECT_EQ(r.summary.taught, (std::vector<std::string>{"my-thing"}));
  EXPECT_EQ(learning->teaches(), 1U);
  LearningAck ack;
  ASSERT_TRUE(client->poll(ack));
  EXPECT_EQ(ack.sequence, sequence);
  EXPECT_EQ(ack.outcome, LearningAck::Outcome::LEARNED);
  EXPECT_EQ(ack.track_id, 1U);
  EXPECT_EQ(ack.label.view(), "my-thing");
  int recognised = 0;
  for (const auto& f : r.frames) {
    for (const auto& o : f["objects"])
      recognised += o["track"] == 1 && o["label"] == "my-thing" ? 1 : 0;
  }
  EXPECT_GE(recognised, 8);  // from the frame after the lesson on
}

TEST(TabletopSession, FindsTheObjectsOfTheRealKinectFrames) {
  auto learning = test::in_memory_learning();
  const std::string dir = std::string(ORTHOFLOW_SHARED_DIR) + "/data/scenes";
  const auto r = run_graph({{"source", {{"kind", "pcd_source"}, {"dir", dir}}}}, 2, *learning);
  ASSERT_EQ(r.frames.size(), 3U);  // test31, test44, test55 in name order
  for (const auto& f : r.frames) {
    EXPECT_TRUE(f["table"].get<bool>()) << f["frame"];
    EXPECT_GE(f["objects"].size(), 2U) << f["frame"];
  }
}

}  // namespace
}  // namespace orthoflow::graphs
