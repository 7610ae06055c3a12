#pragma once
/// @file
/// @brief NodeRegistry: node kinds by name, each with a factory that validates its parameters.
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "engine/node.hpp"
#include "engine/params.hpp"

namespace orthoflow::engine {

/// @brief Builds a node from its parameters; returns a message (without file/line) on bad ones.
/// With NodeContext::mode == BuildMode::CHECK a factory validates exactly as for RUN but connects
/// to nothing outside the process (daemons, devices); the node only has to report its ports.
using NodeFactory =
    std::function<Result<std::unique_ptr<Node>, std::string>(const ParamMap&, const NodeContext&)>;

/// @brief Maps kind names to factories. Filled at start-up, then only read (thread-safe to read).
class NodeRegistry {
 public:
  /// @brief Registers `kind`. @pre kind not yet registered (OF_ENFORCE).
  void add(const std::string& kind, std::string description, NodeFactory factory);
  /// @brief The factory for `kind`, or nullptr if unknown.
  [[nodiscard]] const NodeFactory* find(const std::string& kind) const;
  /// @brief Registered kind names, sorted.
  [[nodiscard]] std::vector<std::string> kinds() const;

 private:
  struct Kind {
    std::string description;
    NodeFactory factory;
  };
  std::map<std::string, Kind> kinds_;
};

/// @brief Adds the domain-free kinds of generic_nodes.hpp (ticker, pass, busy, fanout, join,
/// count).
void add_generic_nodes(NodeRegistry& registry);

}  // namespace orthoflow::engine
