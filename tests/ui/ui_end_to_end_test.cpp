// The web view end to end: the real UiServer on an ephemeral loopback port over a GraphBackend on a
// running tabletop graph (the embedded synthetic session, scripted instructor off) with the real
// LearningService, in memory and over a durable perceptual memory. A person's actions go over HTTP
// through the learning channel and show in the state the server reads back, over HTTP and over the
// WebSocket stream.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <thread>

#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/tabletop.hpp"
#include "http_test_client.hpp"
#include "ui/graph_backend.hpp"
#include "ui/ui_server.hpp"

namespace orthoflow::ui {
namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

/// GET /api/state until @p pred holds on the document (at most @p seconds); the last document.
std::optional<Json> wait_for_state(std::uint16_t port, const std::function<bool(const Json&)>& pred,
                                   int seconds) {
  const auto deadline = Clock::now() + std::chrono::seconds(seconds);
  while (Clock::now() < deadline) {
    const auto r = test::http(port, "GET", "/api/state");
    if (r.status == 200) {
      Json doc = Json::parse(r.body);
      if (pred(doc)) return doc;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return std::nullopt;
}

const Json* object_of(const Json& doc, std::uint64_t track) {
  for (const Json& o : doc["objects"]) {
    if (o["track"] == track && !o["fragment"].get<bool>()) return &o;
  }
  return nullptr;
}

Json post(std::uint16_t port, const std::string& path, const Json& body, int expected_status) {
  const auto r = test::post_json(port, path, body.dump());
  EXPECT_EQ(r.status, expected_status) << path << " " << body.dump() << " -> " << r.body;
  return r.status == 0 ? Json() : Json::parse(r.body);
}

/// A person teaches, asks and forgets through the server while the session runs; @p learned is the
/// outcome of a successful lesson ("learned" in memory, "stored" with a durable memory).
void teach_ask_forget(graphs::LearningService& learning, const std::string& learned) {
  graphs::ObjectsHub hub;
  graphs::SessionLog log(nullptr);
  const auto registry = graphs::make_tabletop_registry(learning, log, &hub);
  auto spec = engine::parse_graph(std::string(graphs::embedded_tabletop_yaml()), "embedded");
  ASSERT_TRUE(spec);
  for (auto& node : spec->nodes) {
    if (node.name == "source") node.params.assign("frames", "1500");
    if (node.name == "recognise") node.params.assign("instructor", "0");
  }
  spec->period_ns = 15'000'000;  // paced, so that the person acts while the session runs
  auto graph = engine::build_graph(*spec, registry);
  ASSERT_TRUE(graph) << engine::to_string(graph.error());
  engine::Engine engine(**graph, {2});
  auto backend = GraphBackend::open(learning, hub);
  ASSERT_TRUE(backend) << backend.error();
  (*backend)->set_telemetry(&engine.stats());
  UiServerConfig config;
  config.ack_timeout_ms = 30'000;  // a loaded machine (or a sanitizer build) may be slow to answer
  config.rate = {1000.0, 1000.0, 64};  // this test polls the state fast, from one address
  auto server = UiServer::start(config, **backend);
  ASSERT_TRUE(server) << server.error();
  const std::uint16_t port = (*server)->port();
  std::thread runner([&] { engine.run({}); });

  // A described, still object seen for a few frames: its track has key views by then.
  std::uint64_t track = 0;
  const auto seen = wait_for_state(
      port,
      [&](const Json& doc) {
        for (const Json& o : doc["objects"]) {
          if (o["described"].get<bool>() && !o["moving"].get<bool>() &&
              !o["fragment"].get<bool>() && doc["frame"].get<std::uint64_t>() >= 5)
            track = o["track"].get<std::uint64_t>();
        }
        return track != 0;
      },
      60);
  ASSERT_TRUE(seen) << "no still, described object appeared";
  EXPECT_TRUE(object_of(*seen, track)->at("label").is_null());  // nothing is known yet
  // The table verdict of the frame (issue 50): the synthetic camera knows where up is.
  EXPECT_EQ((*seen)["table"],
            (Json{{"found", true}, {"reason", "accepted"}, {"gravity", "sensor"}}));

  const Json unknown = post(port, "/api/ask", {{"track", track}}, 200);
  EXPECT_EQ(unknown["outcome"], "answered");
  EXPECT_TRUE(unknown["answer"].is_null());
  EXPECT_TRUE(unknown["nearest"].empty());  // nothing learned: no category is near

  const Json taught = post(port, "/api/teach", {{"track", track}, {"label", "alpha"}}, 200);
  EXPECT_EQ(taught["outcome"], learned);
  EXPECT_EQ(taught["track"], track);
  EXPECT_GE(taught["views"].get<int>(), 2);
  EXPECT_EQ(taught["durable"].get<bool>(), learning.durable());

  const auto labelled = wait_for_state(
      port,
      [&](const Json& doc) {
        const Json* o = object_of(doc, track);
        return o != nullptr && o->at("label") == "alpha";
      },
      30);
  ASSERT_TRUE(labelled) << "the taught label never showed in the state";
  ASSERT_EQ((*labelled)["memory"].size(), 1U);
  EXPECT_EQ((*labelled)["memory"][0]["label"], "alpha");
  EXPECT_GE((*labelled)["memory"][0]["views"].get<int>(), 2);
  EXPECT_FALSE((*labelled)["memory"][0]["last_taught_ms"].is_null());
  const Json& events = (*labelled)["events"];
  ASSERT_GE(events.size(), 2U);
  EXPECT_EQ(events.back()["action"], "teach");
  EXPECT_EQ(events.back()["outcome"], learned);
  EXPECT_FALSE((*labelled)["telemetry"]["nodes"].empty());

  const Json asked = post(port, "/api/ask", {{"track", track}}, 200);
  EXPECT_EQ(asked["answer"], "alpha");
  ASSERT_EQ(asked["nearest"].size(), 1U);  // one category: no runner-up
  EXPECT_EQ(asked["nearest"][0]["label"], "alpha");
  EXPECT_EQ(asked["nearest"][0]["score"], asked["score"]);

  // With a second category the answer names the runner-up with its own decision value: not nearer
  // than the answer (lower is nearer). Then the second category is forgotten again.
  std::uint64_t other = 0;
  for (const Json& o : (*labelled)["objects"]) {
    if (o["described"].get<bool>() && !o["fragment"].get<bool>() && o["track"] != track)
      other = o["track"].get<std::uint64_t>();
  }
  if (other != 0) {
    ASSERT_EQ(post(port, "/api/teach", {{"track", other}, {"label", "beta"}}, 200)["outcome"],
              learned);
    const Json two = post(port, "/api/ask", {{"track", track}}, 200);
    ASSERT_EQ(two["nearest"].size(), 2U) << two.dump();
    EXPECT_EQ(two["nearest"][0]["label"], "alpha");  // its own views
    EXPECT_EQ(two["nearest"][1]["label"], "beta");
    ASSERT_TRUE(two["nearest"][1]["score"].is_number()) << two.dump();
    EXPECT_GE(two["nearest"][1]["score"].get<double>(), two["nearest"][0]["score"].get<double>());
    EXPECT_EQ(post(port, "/api/forget", {{"label", "beta"}}, 200)["outcome"], learned);
  } else {
    ADD_FAILURE() << "only one described object: the runner-up is not checked";
  }

  // The stream carries the same state.
  std::string frame;
  const auto upgrade = test::websocket_first_frame(port, "/api/events?hz=30", frame);
  ASSERT_EQ(upgrade.status, 101) << upgrade.head;
  const Json streamed = Json::parse(frame);
  EXPECT_EQ(streamed["memory"][0]["label"], "alpha");
  EXPECT_GT(streamed["frame"].get<std::uint64_t>(), 0U);

  // The memory is empty and the object Unknown again.
  const auto nothing_known = [&](const Json& doc) {
    const Json* o = object_of(doc, track);
    return doc["memory"].empty() && o != nullptr && o->at("label").is_null();
  };
  // Undo takes the teach back (the memory forgets its views); a second undo has nothing left.
  const Json undone = post(port, "/api/undo", Json::object(), 200);
  EXPECT_EQ(undone["outcome"], learned);
  EXPECT_EQ(undone["label"], "alpha");
  EXPECT_EQ(undone["views"], taught["views"]);
  EXPECT_TRUE(wait_for_state(port, nothing_known, 30))
      << "undoing the only teach did not empty the memory";
  const Json nothing = post(port, "/api/undo", Json::object(), 409);
  EXPECT_EQ(nothing["outcome"], "nothing_to_undo");
  EXPECT_TRUE(nothing["label"].is_null());
  ASSERT_EQ(post(port, "/api/teach", {{"track", track}, {"label", "alpha"}}, 200)["outcome"],
            learned);

  // Errors of the learning channel come back as 4xx with the outcome.
  EXPECT_EQ(post(port, "/api/teach", {{"track", 999999}, {"label", "gamma"}}, 404)["outcome"],
            "no_such_track");
  EXPECT_EQ(post(port, "/api/forget", {{"label", "never"}}, 404)["outcome"], "unknown_label");
  EXPECT_EQ(post(port, "/api/forget", {{"label", "alpha"}}, 200)["outcome"], learned);
  EXPECT_TRUE(wait_for_state(port, nothing_known, 30))
      << "forgetting the category did not make the object Unknown";

  engine.request_stop();
  runner.join();
  server->reset();
  EXPECT_EQ(learning.commands_dropped(), 0U);
}

TEST(UiEndToEnd, TeachAskForgetOverHttpInMemory) {
  graphs::LearningSettings settings;  // the live-session default learner, in memory
  auto learning = graphs::LearningService::open(settings);
  ASSERT_TRUE(learning) << learning.error();
  teach_ask_forget(**learning, "learned");
}

TEST(UiEndToEnd, TeachAskForgetOverHttpDurably) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("orthoflow_ui_e2e_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  graphs::LearningSettings settings;
  settings.db = dir;  // acknowledged as "stored": synced to LevelDB before the answer
  auto learning = graphs::LearningService::open(settings);
  ASSERT_TRUE(learning) << learning.error();
  teach_ask_forget(**learning, "stored");
  learning->reset();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace orthoflow::ui
