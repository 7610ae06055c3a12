// Fuzzes parse_graph (engine/graph_loader.cpp), the graph-file parser every graph command and
// `orthoflow run --graph` go through: no input may crash, hang, leak or hit UB; a refused file must
// say why with a 1-based line (or 0), an accepted one must hold named nodes of known shape.
#include <cstdint>
#include <string>

#include "engine/graph.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto spec = orthoflow::engine::parse_graph(text, "fuzz.yaml");
  if (!spec) {
    if (spec.error().message.empty() || spec.error().line < 0) { __builtin_trap(); }
    return 0;
  }
  for (const auto& node : spec->nodes) {
    if (node.name.empty() || node.kind.empty()) { __builtin_trap(); }
  }
  for (const auto& edge : spec->edges) {
    if (edge.from_node.empty() || edge.to_node.empty()) { __builtin_trap(); }
  }
  if (spec->block_bytes > (std::size_t{1} << 30) || spec->blocks > (std::size_t{1} << 20)) {
    __builtin_trap();
  }
  return 0;
}
