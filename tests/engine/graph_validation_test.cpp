// One test per GraphError code, each checking the code, the file and the line it points at.
#include <gtest/gtest.h>

#include "engine/graph.hpp"
#include "graph_test_util.hpp"

namespace orthoflow::engine {
namespace {

using test::build_yaml;
using Code = GraphError::Code;

// Line numbers below refer to this text (line 1 = "graph:").
const std::string HEADER = "graph:\n  name: t\n  pool: {block_bytes: 256, blocks: 4}\nnodes:\n";
//                           1          2         3                                4
const std::string SRC = "  - {name: src, kind: ticker, params: {frames: 5}}\n";  // line 5
const std::string SINK = "  - {name: sink, kind: count}\n";                      // line 6

void expect_error(const std::string& yaml, Code code, int line, const std::string& needle) {
  const auto built = build_yaml(yaml, "bad.yaml");
  ASSERT_FALSE(built.graph) << "expected " << to_string(code);
  EXPECT_EQ(built.error.code, code) << to_string(built.error);
  EXPECT_EQ(built.error.line, line) << to_string(built.error);
  EXPECT_EQ(built.error.file, "bad.yaml");
  const std::string text = to_string(built.error);
  EXPECT_NE(text.find(needle), std::string::npos) << text;
  EXPECT_EQ(text.rfind("bad.yaml:" + std::to_string(line) + ": error [" + to_string(code) + "]", 0),
            0u)
      << text;
}

TEST(GraphValidation, AcceptsAMinimalGraph) {
  const auto built = build_yaml(HEADER + SRC + SINK + "edges:\n  - src.out -> sink.in\n");
  ASSERT_TRUE(built.graph) << to_string(built.error);
  EXPECT_EQ(built.graph->edges.size(), 1u);
  EXPECT_EQ(built.graph->max_in_flight, 4u);
  EXPECT_EQ(built.graph->topo_order.front(), built.graph->source);
  const std::string dot = to_dot(*built.graph);
  EXPECT_NE(dot.find("\"src\" -> \"sink\""), std::string::npos) << dot;
}

TEST(GraphValidation, ExampleGraphFileIsValid) {
  auto spec_result = load_graph_file(ORTHOFLOW_SOURCE_DIR "/graphs/example_pipeline.yaml");
  ASSERT_TRUE(spec_result) << to_string(spec_result.error());
  auto graph_result = build_graph(*spec_result, test::generic_registry());
  ASSERT_TRUE(graph_result) << to_string(graph_result.error());
}

TEST(GraphValidation, FileUnreadable) {
  auto spec_result = load_graph_file("/nonexistent/graph.yaml");
  ASSERT_FALSE(spec_result);
  EXPECT_EQ(spec_result.error().code, Code::FILE_UNREADABLE);
  EXPECT_NE(to_string(spec_result.error()).find("/nonexistent/graph.yaml"), std::string::npos);
}

TEST(GraphValidation, SyntaxErrorNamesLine) {
  expect_error(HEADER + SRC + "  - {name: sink, kind: [count}\n", Code::SYNTAX, 6, "");
}

TEST(GraphValidation, BadStructure) {
  expect_error(HEADER + SRC + SINK + "edges:\n  - src.out => sink.in\n", Code::BAD_STRUCTURE, 8,
               "node.port -> node.port");
  expect_error(HEADER + SRC + "  - {name: sink}\n", Code::BAD_STRUCTURE, 6, "'kind'");
}

// A key twice in one map is an error naming the second one's line, at any depth (issue 52, item
// 11): yaml-cpp keeps both and the loader would silently take one of them.
TEST(GraphValidation, AKeyTwiceInOneMap) {
  expect_error(HEADER + "  - {name: src, kind: ticker, params: {frames: 5, frames: 9}}\n" + SINK,
               Code::BAD_STRUCTURE, 5, "key 'frames' appears twice in one map");
  expect_error("graph:\n  name: t\n  name: u\n", Code::BAD_STRUCTURE, 3,
               "key 'name' appears twice in one map");
  expect_error(HEADER + SRC + SINK + "edges:\n  - src.out -> sink.in\nnodes: []\n",
               Code::BAD_STRUCTURE, 9, "key 'nodes' appears twice");
  // The same key in two maps is fine.
  const auto built = build_yaml(HEADER + SRC + SINK + "edges:\n  - src.out -> sink.in\n");
  EXPECT_TRUE(built.graph) << to_string(built.error);
}

// Aliases can make a small file a tree of billions of nodes: the key check stops at
// core::YAML_MAX_NODES instead of walking it.
TEST(GraphValidation, AnAliasBombIsRefusedQuickly) {
  std::string yaml = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 12; ++i) {
    yaml += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) yaml += (k ? ", *a" : "*a") + std::to_string(i - 1);
    yaml += "]\n";
  }
  const auto built = build_yaml(yaml, "bad.yaml");
  ASSERT_FALSE(built.graph);
  EXPECT_EQ(built.error.code, Code::BAD_STRUCTURE);
  EXPECT_NE(to_string(built.error).find("YAML nodes (aliases?)"), std::string::npos)
      << to_string(built.error);
}

TEST(GraphValidation, DuplicateNode) {
  expect_error(HEADER + SRC + "  - {name: src, kind: count}\n", Code::DUPLICATE_NODE, 6, "'src'");
}

TEST(GraphValidation, UnknownKind) {
  expect_error(HEADER + SRC + "  - {name: sink, kind: teleport}\n", Code::UNKNOWN_KIND, 6,
               "'teleport'");
}

TEST(GraphValidation, UnknownNode) {
  expect_error(HEADER + SRC + SINK + "edges:\n  - src.out -> sinc.in\n", Code::UNKNOWN_NODE, 8,
               "'sinc'");
}

TEST(GraphValidation, UnknownPort) {
  expect_error(HEADER + SRC + SINK + "edges:\n  - src.out -> sink.input\n", Code::UNKNOWN_PORT, 8,
               "'input'");
  expect_error(HEADER + SRC + SINK + "edges:\n  - src.output -> sink.in\n", Code::UNKNOWN_PORT, 8,
               "'output'");
}

TEST(GraphValidation, TypeMismatch) {
  expect_error(
      HEADER + SRC +
          "  - {name: sink, kind: count, params: {type: object}}\nedges:\n  - src.out -> sink.in\n",
      Code::TYPE_MISMATCH, 8, "'frame'");
}

TEST(GraphValidation, UnconnectedRequiredInput) {
  expect_error(HEADER + SRC + SINK, Code::UNCONNECTED_INPUT, 6, "sink.in");
}

TEST(GraphValidation, Cycle) {
  const std::string nodes = HEADER + SRC + "  - {name: a, kind: pass}\n  - {name: b, kind: pass}\n";
  expect_error(nodes + "edges:\n  - src.out -> a.in\n  - a.out -> b.in\n  - b.out -> a.in\n",
               Code::CYCLE, 6, "a -> b -> a");
}

TEST(GraphValidation, BadParameterNamesKeyAndLine) {
  expect_error(HEADER + "  - name: src\n    kind: ticker\n    params:\n      frames: -3\n" + SINK,
               Code::BAD_PARAMETER, 5, "parameter 'frames' (line 8)");
  expect_error(HEADER + SRC + "  - {name: sink, kind: count, params: {colour: red}}\n",
               Code::BAD_PARAMETER, 6, "'colour'");
  expect_error(HEADER + SRC + "  - {name: sink, kind: count, policy: newest}\n",
               Code::BAD_PARAMETER, 6, "newest");
  expect_error("graph:\n  period_ms: fast\nnodes:\n" + SRC, Code::BAD_PARAMETER, 2, "period_ms");
}

TEST(GraphValidation, SourceCount) {
  expect_error(HEADER + SRC + "  - {name: src2, kind: ticker}\n", Code::SOURCE_COUNT, 5, "found 2");
  expect_error(HEADER + SINK, Code::SOURCE_COUNT, 5, "found 0");
}

TEST(GraphValidation, PoolErrors) {
  expect_error("graph:\n  pool: {block_bytes: 0, blocks: 2}\nnodes:\n" + SRC, Code::POOL, 2,
               "block_bytes");  // the pool's own line
  expect_error("graph:\n  max_in_flight: 9\n  pool: {blocks: 4}\nnodes:\n" + SRC, Code::POOL, 0,
               "exceeds");
}

TEST(ParamMap, TypedGettersReportKeyAndLine) {
  ParamMap params;
  params.set("n", "12", 3);
  params.set("word", "x7", 4);
  EXPECT_EQ(*params.integer("n", 0, 0, 20), 12);
  EXPECT_EQ(*params.integer("missing", 5, 0, 20), 5);
  const auto range = params.integer("n", 0, 0, 10);
  ASSERT_FALSE(range);
  EXPECT_NE(range.error().find("line 3"), std::string::npos);
  EXPECT_FALSE(params.integer("word", 0, 0, 10));
  EXPECT_FALSE(params.choice("word", "a", {"a", "b"}));
  EXPECT_FALSE(params.only({"n"}));
  EXPECT_TRUE(params.only({"n", "word"}));
}

}  // namespace
}  // namespace orthoflow::engine

namespace orthoflow::engine {
namespace {

TEST(GraphValidation, DuplicateEdgesAndUnsafeNamesAreRefusedWithTheirLine) {
  // The same edge twice would deliver every message twice (a sink counted 40 messages for 20
  // frames).
  expect_error(HEADER + SRC + SINK + "edges:\n  - src.out -> sink.in\n  - src.out -> sink.in\n",
               Code::BAD_STRUCTURE, 9, "listed twice");
  // Names end up in DOT, iceoryx topics and messages: a quote, a slash or a space is refused.
  expect_error(
      "graph:\n  name: 'a\"b'\n  pool: {block_bytes: 256, blocks: 4}\nnodes:\n" + SRC + SINK,
      Code::BAD_PARAMETER, 2, "graph.name");
  expect_error(HEADER + "  - {name: 'my node', kind: ticker}\n" + SINK, Code::BAD_PARAMETER, 5,
               "node name");
  expect_error(HEADER + SRC + "  - {name: a/b, kind: count}\n", Code::BAD_PARAMETER, 6,
               "node name");
}

}  // namespace
}  // namespace orthoflow::engine
