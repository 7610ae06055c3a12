#pragma once
/// @file
/// @brief One rule for every YAML file the product reads (graphs, robot.yaml, robot frames, arm
/// limits, the bridge's config): a key appears once in its map. yaml-cpp keeps both entries of a
/// duplicate key, and a reader then takes the first or the last without a word, so a file that
/// says two things gets one of them silently (issue 52, item 11). Header-only, for the readers,
/// which link yaml-cpp themselves; core's library does not use it.
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <set>
#include <string>

#include "core/result.hpp"

namespace orthoflow::core {

/// Nodes a check visits at most: aliases can make a small file a tree of billions of nodes.
inline constexpr std::size_t YAML_MAX_NODES = 100'000;

/// @brief What check_unique_keys found: the line (1-based; 0 when the problem has none) and what.
struct YamlKeyProblem {
  int line = 0;
  std::string what;
  [[nodiscard]] std::string to_string() const {
    return line > 0 ? "line " + std::to_string(line) + ": " + what : what;
  }
};

namespace detail {

inline Result<void, YamlKeyProblem> unique_keys(const YAML::Node& node, std::size_t& visited) {
  if (++visited > YAML_MAX_NODES)
    return err(YamlKeyProblem{
        0, "more than " + std::to_string(YAML_MAX_NODES) + " YAML nodes (aliases?)"});
  if (node.IsMap()) {
    std::set<std::string> seen;
    for (const auto& kv : node) {
      if (kv.first.IsScalar() && !seen.insert(kv.first.Scalar()).second)
        return err(YamlKeyProblem{kv.first.Mark().line + 1,
                                  "key '" + kv.first.Scalar() + "' appears twice in one map"});
      if (auto r = unique_keys(kv.second, visited); !r) return r;
    }
  } else if (node.IsSequence()) {
    for (const auto& item : node)
      if (auto r = unique_keys(item, visited); !r) return r;
  }
  return {};
}

}  // namespace detail

/// @brief Every map in @p root has each key once; the error names the line and the key.
[[nodiscard]] inline Result<void, YamlKeyProblem> check_unique_keys(const YAML::Node& root) {
  std::size_t visited = 0;
  return detail::unique_keys(root, visited);
}

}  // namespace orthoflow::core
