#pragma once
// Runs the embedded tabletop graph with parameter overrides (test helper).
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/tabletop.hpp"

namespace orthoflow::graphs::test {

/// node name -> {key -> value} overrides; a "kind" key replaces the node kind (and its params).
using Overrides = std::map<std::string, std::map<std::string, std::string>>;

inline engine::GraphSpec tabletop_spec(const Overrides& overrides) {
  auto spec = engine::parse_graph(std::string(embedded_tabletop_yaml()), "embedded");
  EXPECT_TRUE(spec) << engine::to_string(spec.error());
  for (auto& node : spec->nodes) {
    const auto it = overrides.find(node.name);
    if (it == overrides.end()) continue;
    if (const auto kind = it->second.find("kind"); kind != it->second.end()) {
      node.kind = kind->second;
      node.params = {};
    }
    for (const auto& [key, value] : it->second) {
      if (key != "kind") node.params.assign(key, value);
    }
  }
  spec->period_ns = 0;  // as fast as the graph goes
  return *spec;
}

inline std::unique_ptr<LearningService> in_memory_learning() {
  LearningSettings settings;  // the live-session default: plain NN, CT = DEFAULT_NN_THRESHOLD
  auto service = LearningService::open(settings);
  EXPECT_TRUE(service) << service.error();
  return std::move(*service);
}

}  // namespace orthoflow::graphs::test
