// BuildMode::CHECK: graphs with the IPC kinds validate completely without RouDi, report every bad
// parameter with the same message and line as BuildMode::RUN, connect to nothing, and cannot run.
#include <gtest/gtest.h>

#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "engine/ipc_nodes.hpp"
#include "engine/ipc_runtime.hpp"

namespace orthoflow::engine {
namespace {

using Code = GraphError::Code;

const NodeRegistry& ipc_registry() {
  static const NodeRegistry registry = [] {
    NodeRegistry r;
    add_generic_nodes(r);
    add_ipc_nodes(r);
    return r;
  }();
  return registry;
}

// Line numbers below refer to these texts (line 1 = "graph:"); the IPC node is on line 5.
const std::string HEADER = "graph:\n  name: t\n  pool: {block_bytes: 100000, blocks: 4}\nnodes:\n";
std::string publisher_graph(const std::string& params) {
  return HEADER + "  - {name: pub, kind: ipc_publish, params: {" + params + "}}\n" +
         "  - {name: src, kind: ticker, params: {frames: 5}}\nedges:\n  - src.out -> pub.in\n";
}
std::string subscriber_graph(const std::string& params) {
  return HEADER + "  - {name: sub, kind: ipc_subscribe, params: {" + params + "}}\n" +
         "  - {name: sink, kind: count}\nedges:\n  - sub.out -> sink.in\n";
}

Result<std::unique_ptr<Graph>, GraphError> build(const std::string& yaml, BuildMode mode) {
  auto spec_result = parse_graph(yaml, "ipc.yaml");
  if (!spec_result) return err(spec_result.error());
  return build_graph(*spec_result, ipc_registry(), mode);
}

TEST(GraphCheckMode, IpcGraphsValidateWithoutConnecting) {
  auto publisher =
      build(publisher_graph("topic: orthoflow/test/frames, history: 2"), BuildMode::CHECK);
  ASSERT_TRUE(publisher) << to_string(publisher.error());
  auto subscriber = build(subscriber_graph("topic: orthoflow/test/frames, policy: queue, depth: 8"),
                          BuildMode::CHECK);
  ASSERT_TRUE(subscriber) << to_string(subscriber.error());
  EXPECT_EQ((*publisher)->mode, BuildMode::CHECK);
  EXPECT_EQ((*subscriber)->edges.size(), 1u);
  EXPECT_EQ((*subscriber)->nodes[(*subscriber)->source]->outputs()[0].type, "frame");
  const auto* ipc = dynamic_cast<const IpcNode*>((*publisher)->nodes[0].get());
  ASSERT_NE(ipc, nullptr);
  EXPECT_EQ(ipc->topic(), "orthoflow/test/frames");
  EXPECT_NE(to_dot(**publisher).find("pub\\nipc_publish\\nserial"), std::string::npos)
      << to_dot(**publisher);
  // A RouDi TOML file named in the graph is read and its pools checked, still without a RouDi.
  const std::string config = ORTHOFLOW_SOURCE_DIR "/config/roudi_test.toml";
  auto with_config =
      build(publisher_graph("topic: a/b/c, roudi_config: " + config + ", max_bytes: 60000"),
            BuildMode::CHECK);
  ASSERT_TRUE(with_config) << to_string(with_config.error());
  EXPECT_FALSE(ipc_runtime_ready()) << "CHECK registered this process with RouDi";
}

// Each bad parameter: CHECK fails with exactly RUN's error (RUN finds it before it connects).
TEST(GraphCheckMode, BadIpcParametersAreReportedAsInRunMode) {
  const struct {
    std::string yaml, needle;
  } cases[] = {
      {publisher_graph("topic: a/b/c, history: 99"),
       "parameter 'history' (line 5): 99 is outside [0, 16]"},
      {publisher_graph("topic: a/b/c, colour: red"), "'colour'"},
      {publisher_graph("topic: a/b, type: frame"), "BAD_TOPIC"},
      {publisher_graph("topic: a/b/c, type: pointcloud"), "'pointcloud'"},
      {publisher_graph("topic: a/b/c, roudi_config: /nonexistent/roudi.toml"),
       "CONFIG: RouDi config '/nonexistent"},
      {subscriber_graph("topic: a/b/c, policy: newest"), "'newest'"},
      {subscriber_graph("topic: a/b/c, depth: 253"),
       "253 is outside [1, 252] (256 minus the pool's blocks)"},
      {subscriber_graph("topic: a//c"), "BAD_TOPIC"},
  };
  for (const auto& c : cases) {
    auto checked = build(c.yaml, BuildMode::CHECK);
    ASSERT_FALSE(checked) << c.yaml;
    EXPECT_EQ(checked.error().code, Code::BAD_PARAMETER) << to_string(checked.error());
    EXPECT_EQ(checked.error().line, 5) << to_string(checked.error());
    EXPECT_NE(to_string(checked.error()).find(c.needle), std::string::npos)
        << to_string(checked.error());
    auto run = build(c.yaml, BuildMode::RUN);
    ASSERT_FALSE(run) << c.yaml;
    EXPECT_EQ(to_string(run.error()), to_string(checked.error()));
  }
  EXPECT_FALSE(ipc_runtime_ready());
}

TEST(GraphCheckMode, PayloadLargerThanTheNamedPoolsIsReported) {
  // roudi_test.toml's largest pool holds 64 KiB payloads; max_bytes defaults to the 100000 B
  // blocks.
  auto checked = build(publisher_graph("topic: a/b/c, roudi_config: " ORTHOFLOW_SOURCE_DIR
                                       "/config/roudi_test.toml"),
                       BuildMode::CHECK);
  ASSERT_FALSE(checked);
  EXPECT_EQ(checked.error().code, Code::BAD_PARAMETER);
  EXPECT_EQ(checked.error().line, 5);
  EXPECT_NE(to_string(checked.error()).find("NO_FITTING_POOL: publisher a/b/c: a 100000 B payload"),
            std::string::npos)
      << to_string(checked.error());
}

TEST(GraphCheckMode, RunModeStillConnects) {
  if (probe_roudi()) GTEST_SKIP() << "a RouDi is running: RUN would connect to it";
  for (const auto& yaml : {publisher_graph("topic: a/b/c"), subscriber_graph("topic: a/b/c")}) {
    auto run = build(yaml, BuildMode::RUN);
    ASSERT_FALSE(run);
    EXPECT_EQ(run.error().code, Code::BAD_PARAMETER);
    EXPECT_NE(to_string(run.error()).find("ROUDI_UNREACHABLE"), std::string::npos)
        << to_string(run.error());
  }
}

TEST(GraphCheckModeDeathTest, EngineRefusesACheckGraph) {
  auto checked = build(subscriber_graph("topic: a/b/c"), BuildMode::CHECK);
  ASSERT_TRUE(checked) << to_string(checked.error());
  EXPECT_DEATH(Engine(**checked, EngineConfig{1}), "BuildMode::CHECK");
}

}  // namespace
}  // namespace orthoflow::engine
