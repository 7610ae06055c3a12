// Validation and instantiation of a GraphSpec. Checks run in the order a reader would fix them:
// pool, kinds and parameters, sources, edges (node, port, type), required inputs, cycles.
#include <algorithm>
#include <functional>
#include <map>
#include <optional>
#include <set>

#include <unistd.h>

#include "engine/graph.hpp"

namespace orthoflow::engine {

namespace {

using Code = GraphError::Code;
using Built = Result<std::unique_ptr<Graph>, GraphError>;

// Physical memory of this machine in bytes (0 if unknown).
std::size_t physical_memory_bytes() noexcept {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? static_cast<std::size_t>(pages) * static_cast<std::size_t>(page)
                               : 0;
}

GraphError error_at(const GraphSpec& spec, Code code, int line, std::string message) {
  return GraphError{code, spec.file, line, std::move(message)};
}

std::optional<std::size_t> port_index(std::span<const PortSpec> ports, const std::string& name) {
  for (std::size_t i = 0; i < ports.size(); ++i) {
    if (ports[i].name == name) return i;
  }
  return std::nullopt;
}

std::string port_list(std::span<const PortSpec> ports) {
  std::string list;
  for (const auto& p : ports) list += (list.empty() ? "" : ", ") + p.name + ":" + p.type;
  return list.empty() ? "none" : list;
}

std::optional<GraphError> make_nodes(Graph& graph, const NodeRegistry& registry) {
  const GraphSpec& spec = graph.spec;
  for (const auto& node : spec.nodes) {
    const NodeFactory* factory = registry.find(node.kind);
    if (factory == nullptr) {
      std::string known;
      for (const auto& k : registry.kinds()) known += (known.empty() ? "" : ", ") + k;
      return error_at(
          spec, Code::UNKNOWN_KIND, node.line,
          "node '" + node.name + "': unknown kind '" + node.kind + "' (known: " + known + ")");
    }
    const NodeContext context{node.name, graph.pool.get(), graph.max_in_flight, graph.mode, &spec};
    auto node_result = (*factory)(node.params, context);
    if (!node_result) {
      return error_at(spec, Code::BAD_PARAMETER, node.line,
                      "node '" + node.name + "': " + node_result.error());
    }
    graph.nodes.push_back(std::move(*node_result));
  }
  std::vector<std::string> sources;
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    if (graph.nodes[i]->inputs().empty()) {
      graph.source = i;
      sources.push_back(spec.nodes[i].name);
    }
  }
  if (sources.size() != 1) {
    std::string names;
    for (const auto& s : sources) names += " '" + s + "'";
    return error_at(spec, Code::SOURCE_COUNT, spec.nodes.empty() ? 0 : spec.nodes.front().line,
                    "a graph needs exactly one source node (no inputs), found " +
                        std::to_string(sources.size()) + names);
  }
  return std::nullopt;
}

std::optional<GraphError> resolve_edges(Graph& graph) {
  const GraphSpec& spec = graph.spec;
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < spec.nodes.size(); ++i) index[spec.nodes[i].name] = i;
  std::set<std::string> seen;  // the same edge twice would deliver every message twice
  for (const auto& e : spec.edges) {
    if (!seen.insert(e.from_node + "." + e.from_port + "->" + e.to_node + "." + e.to_port).second) {
      return error_at(spec, Code::BAD_STRUCTURE, e.line,
                      "edge " + e.from_node + "." + e.from_port + " -> " + e.to_node + "." +
                          e.to_port + " is listed twice");
    }
    const auto from = index.find(e.from_node);
    const auto to = index.find(e.to_node);
    if (from == index.end() || to == index.end()) {
      const std::string& missing = from == index.end() ? e.from_node : e.to_node;
      return error_at(spec, Code::UNKNOWN_NODE, e.line,
                      "edge names unknown node '" + missing + "'");
    }
    const auto outs = graph.nodes[from->second]->outputs();
    const auto ins = graph.nodes[to->second]->inputs();
    const auto out_port = port_index(outs, e.from_port);
    if (!out_port) {
      return error_at(spec, Code::UNKNOWN_PORT, e.line,
                      "node '" + e.from_node + "' has no output port '" + e.from_port +
                          "' (outputs: " + port_list(outs) + ")");
    }
    const auto in_port = port_index(ins, e.to_port);
    if (!in_port) {
      return error_at(spec, Code::UNKNOWN_PORT, e.line,
                      "node '" + e.to_node + "' has no input port '" + e.to_port +
                          "' (inputs: " + port_list(ins) + ")");
    }
    if (outs[*out_port].type != ins[*in_port].type) {
      return error_at(spec, Code::TYPE_MISMATCH, e.line,
                      e.from_node + "." + e.from_port + " carries '" + outs[*out_port].type +
                          "' but " + e.to_node + "." + e.to_port + " expects '" +
                          ins[*in_port].type + "'");
    }
    graph.edges.push_back({from->second, *out_port, to->second, *in_port});
  }
  return std::nullopt;
}

std::optional<GraphError> check_required_inputs(const Graph& graph) {
  const GraphSpec& spec = graph.spec;
  for (std::size_t n = 0; n < graph.nodes.size(); ++n) {
    const auto ins = graph.nodes[n]->inputs();
    for (std::size_t p = 0; p < ins.size(); ++p) {
      const bool connected =
          std::any_of(graph.edges.begin(), graph.edges.end(),
                      [&](const Edge& e) { return e.to_node == n && e.to_port == p; });
      if (ins[p].required && !connected) {
        return error_at(
            spec, Code::UNCONNECTED_INPUT, spec.nodes[n].line,
            "required input '" + spec.nodes[n].name + "." + ins[p].name + "' has no incoming edge");
      }
    }
  }
  return std::nullopt;
}

// Depth-first search with colours; on a back edge the grey stack is the cycle, reported in full.
std::optional<GraphError> order_nodes(Graph& graph) {
  const std::size_t n = graph.nodes.size();
  std::vector<int> colour(n, 0);
  std::vector<std::size_t> stack;
  std::vector<std::size_t> post;
  std::optional<GraphError> cycle;
  std::function<void(std::size_t)> visit = [&](std::size_t v) {
    colour[v] = 1;
    stack.push_back(v);
    for (const auto& e : graph.edges) {
      if (e.from_node != v || cycle) continue;
      if (colour[e.to_node] == 1) {
        std::string path;
        const auto start = std::find(stack.begin(), stack.end(), e.to_node);
        for (auto it = start; it != stack.end(); ++it) path += graph.spec.nodes[*it].name + " -> ";
        path += graph.spec.nodes[e.to_node].name;
        cycle = error_at(graph.spec, Code::CYCLE, graph.spec.nodes[e.to_node].line,
                         "cycle " + path + " (a dataflow graph must be acyclic)");
      } else if (colour[e.to_node] == 0) {
        visit(e.to_node);
      }
    }
    stack.pop_back();
    colour[v] = 2;
    post.push_back(v);
  };
  for (std::size_t v = 0; v < n && !cycle; ++v) {
    if (colour[v] == 0) visit(v);
  }
  if (cycle) return cycle;
  graph.topo_order.assign(post.rbegin(), post.rend());
  return std::nullopt;
}

}  // namespace

std::string to_string(GraphError::Code code) {
  static const char* const NAMES[] = {
      "FILE_UNREADABLE", "SYNTAX",       "BAD_STRUCTURE", "DUPLICATE_NODE",    "UNKNOWN_KIND",
      "UNKNOWN_NODE",    "UNKNOWN_PORT", "TYPE_MISMATCH", "UNCONNECTED_INPUT", "CYCLE",
      "BAD_PARAMETER",   "SOURCE_COUNT", "POOL"};
  return NAMES[static_cast<std::size_t>(code)];
}

std::string to_string(const GraphError& error) {
  return error.file + ":" + std::to_string(error.line) + ": error [" + to_string(error.code) +
         "]: " + error.message;
}

Built build_graph(const GraphSpec& spec, const NodeRegistry& registry, BuildMode mode) {
  auto graph = std::make_unique<Graph>();
  graph->spec = spec;
  graph->mode = mode;
  graph->max_in_flight = spec.max_in_flight == 0 ? spec.blocks : spec.max_in_flight;
  if (graph->max_in_flight > spec.blocks) {
    return err(error_at(spec, Code::POOL, 0,
                        "max_in_flight " + std::to_string(graph->max_in_flight) +
                            " exceeds the pool's " + std::to_string(spec.blocks) +
                            " blocks (the limiter is sized to the pool)"));
  }
  // Each field within its limit can still ask for more memory than the machine has (1 GiB x 2^20
  // blocks): refuse it like every other graph error, before allocating anything.
  const memory_pool::PoolConfig pool_config{spec.block_bytes, spec.blocks, graph->spec.name};
  const std::size_t needed = memory_pool::required_bytes(pool_config);
  const std::size_t physical = physical_memory_bytes();
  if (needed != 0 && physical != 0 && needed > physical) {
    return err(error_at(spec, Code::POOL, spec.pool_line,
                        "the pool needs " + std::to_string(needed >> 20) + " MiB (block_bytes " +
                            std::to_string(spec.block_bytes) + " x blocks " +
                            std::to_string(spec.blocks) + "), more than this machine's " +
                            std::to_string(physical >> 20) + " MiB"));
  }
  auto pool_result = memory_pool::BlockPool::create_owned(pool_config);
  if (!pool_result)
    return err(
        error_at(spec, Code::POOL, spec.pool_line, memory_pool::to_string(pool_result.error())));
  graph->pool = std::move(*pool_result);
  if (auto e = make_nodes(*graph, registry)) return err(*e);
  if (auto e = resolve_edges(*graph)) return err(*e);
  if (auto e = check_required_inputs(*graph)) return err(*e);
  if (auto e = order_nodes(*graph)) return err(*e);
  return graph;
}

std::string to_dot(const Graph& graph) {
  std::string dot = "digraph \"" + graph.spec.name + "\" {\n  rankdir=LR;\n  node [shape=box];\n";
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    const NodeSpec& n = graph.spec.nodes[i];
    std::string label = n.name + "\\n" + n.kind;
    if (graph.nodes[i]->stateful()) label += "\\nserial";
    if (n.policy == Policy::LATEST) label += "\\nlatest-wins";
    if (n.ordered) label += "\\nordered";
    dot += "  \"" + n.name + "\" [label=\"" + label + "\"" +
           (i == graph.source ? ", shape=invhouse" : "") + "];\n";
  }
  for (const auto& e : graph.edges) {
    const auto& out = graph.nodes[e.from_node]->outputs()[e.from_port];
    const auto& in = graph.nodes[e.to_node]->inputs()[e.to_port];
    dot += "  \"" + graph.spec.nodes[e.from_node].name + "\" -> \"" +
           graph.spec.nodes[e.to_node].name + "\" [label=\"" + out.name + "->" + in.name + " (" +
           out.type + ")\"];\n";
  }
  return dot + "}\n";
}

}  // namespace orthoflow::engine
