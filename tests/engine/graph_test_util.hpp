#pragma once
// Helpers shared by the engine tests: build a graph from YAML text with the generic registry.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "engine/graph.hpp"
#include "engine/registry.hpp"

namespace orthoflow::engine::test {

inline const NodeRegistry& generic_registry() {
  static const NodeRegistry registry = [] {
    NodeRegistry r;
    add_generic_nodes(r);
    return r;
  }();
  return registry;
}

/// Parses and builds; on failure returns the error (graph is null).
struct Built {
  std::unique_ptr<Graph> graph;
  GraphError error;
};

inline Built build_yaml(const std::string& yaml, const std::string& file = "test.yaml") {
  auto spec_result = parse_graph(yaml, file);
  if (!spec_result) return {nullptr, spec_result.error()};
  auto graph_result = build_graph(*spec_result, generic_registry());
  if (!graph_result) return {nullptr, graph_result.error()};
  return {std::move(*graph_result), {}};
}

inline std::unique_ptr<Graph> must_build(const std::string& yaml) {
  auto built = build_yaml(yaml);
  EXPECT_TRUE(built.graph) << to_string(built.error);
  return std::move(built.graph);
}

}  // namespace orthoflow::engine::test
