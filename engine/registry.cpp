#include "engine/registry.hpp"

#include "core/assert.hpp"

namespace orthoflow::engine {

void NodeRegistry::add(const std::string& kind, std::string description, NodeFactory factory) {
  OF_ENFORCE(kinds_.find(kind) == kinds_.end(), "node kind registered twice");
  kinds_.emplace(kind, Kind{std::move(description), std::move(factory)});
}

const NodeFactory* NodeRegistry::find(const std::string& kind) const {
  const auto it = kinds_.find(kind);
  return it == kinds_.end() ? nullptr : &it->second.factory;
}

std::vector<std::string> NodeRegistry::kinds() const {
  std::vector<std::string> names;
  for (const auto& [name, kind] : kinds_) names.push_back(name);
  return names;
}

}  // namespace orthoflow::engine
