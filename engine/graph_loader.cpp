// Graph file parsing (yaml-cpp). Every error names the file and the 1-based line of the offending
// YAML node (yaml-cpp marks are 0-based).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

#include "core/regular_file.hpp"
#include "core/yaml_keys.hpp"
#include "engine/graph.hpp"

namespace orthoflow::engine {

namespace {

using Code = GraphError::Code;

struct Fail {
  GraphError error;
};

int line_of(const YAML::Node& node) { return node.Mark().line >= 0 ? node.Mark().line + 1 : 0; }

[[noreturn]] void fail(Code code, const std::string& file, const YAML::Node& at,
                       const std::string& message) {
  throw Fail{GraphError{code, file, line_of(at), message}};
}

std::string scalar(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node.IsScalar()) fail(Code::BAD_STRUCTURE, file, node, what + " must be a scalar");
  return node.Scalar();
}

double number(const YAML::Node& node, const std::string& file, const std::string& what,
              double max) {
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value) ||
      value < 0.0 || value > max) {
    fail(Code::BAD_PARAMETER, file, node,
         what + " must be a number in [0, " + std::to_string(max) + "]");
  }
  return value;
}

// A count of bytes or blocks: a whole number (4096.5 bytes is not a size).
std::size_t whole(const YAML::Node& node, const std::string& file, const std::string& what,
                  double max) {
  const double value = number(node, file, what, max);
  if (value != std::floor(value))
    fail(Code::BAD_PARAMETER, file, node, what + " must be a whole number");
  return static_cast<std::size_t>(value);
}

// A graph or node name: letters, digits, '_', '-' and '.', at most 64 of them. Names end up in DOT
// files, iceoryx topics (orthoflow/<graph>/objects), telemetry and error messages, where a quote, a
// slash or a space would break them.
std::string identifier(const YAML::Node& node, const std::string& file, const std::string& what) {
  const std::string name = scalar(node, file, what);
  const bool ok =
      !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.';
      });
  if (!ok)
    fail(Code::BAD_PARAMETER, file, node,
         what + " '" + name + "' must be 1-64 letters, digits, '_', '-' or '.'");
  return name;
}

void parse_header(const YAML::Node& graph, GraphSpec& spec) {
  if (!graph) return;
  if (!graph.IsMap()) fail(Code::BAD_STRUCTURE, spec.file, graph, "'graph' must be a map");
  for (const auto& item : graph) {
    const std::string key = item.first.Scalar();
    const YAML::Node& value = item.second;
    if (key == "name") {
      spec.name = identifier(value, spec.file, "graph.name");
    } else if (key == "period_ms") {
      spec.period_ns =
          static_cast<std::int64_t>(number(value, spec.file, "graph.period_ms", 3.6e6) * 1e6);
    } else if (key == "max_in_flight") {
      spec.max_in_flight =
          static_cast<std::size_t>(number(value, spec.file, "graph.max_in_flight", 4096));
    } else if (key == "pool" && value.IsMap()) {
      spec.pool_line = value.Mark().line + 1;
      for (const auto& p : value) {
        const std::string pkey = p.first.Scalar();
        if (pkey == "block_bytes") {
          spec.block_bytes = whole(p.second, spec.file, "pool.block_bytes", 1 << 30);
        } else if (pkey == "blocks") {
          spec.blocks = whole(p.second, spec.file, "pool.blocks", 1 << 20);
        } else {
          fail(Code::BAD_PARAMETER, spec.file, p.first, "unknown pool key '" + pkey + "'");
        }
      }
    } else {
      fail(Code::BAD_PARAMETER, spec.file, item.first, "unknown graph key '" + key + "'");
    }
  }
}

void parse_node_key(const std::string& key, const YAML::Node& value, NodeSpec& node,
                    const std::string& file) {
  if (key == "name") {
    node.name = identifier(value, file, "node name");
  } else if (key == "kind") {
    node.kind = scalar(value, file, "node kind");
  } else if (key == "policy") {
    const std::string policy = scalar(value, file, "policy");
    if (policy != "queue" && policy != "latest") {
      fail(Code::BAD_PARAMETER, file, value,
           "policy '" + policy + "' is not one of {queue, latest}");
    }
    node.policy = policy == "latest" ? Policy::LATEST : Policy::QUEUE;
  } else if (key == "ordered") {
    bool ordered = false;
    if (!value.IsScalar() || !YAML::convert<bool>::decode(value, ordered)) {
      fail(Code::BAD_PARAMETER, file, value, "ordered must be true or false");
    }
    node.ordered = ordered;
  } else if (key == "deadline_ms") {
    node.deadline_ns = static_cast<std::int64_t>(number(value, file, "deadline_ms", 3.6e6) * 1e6);
  } else if (key == "params") {
    if (!value.IsMap()) fail(Code::BAD_STRUCTURE, file, value, "params must be a map");
    for (const auto& p : value) {
      node.params.set(p.first.Scalar(),
                      scalar(p.second, file, "parameter '" + p.first.Scalar() + "'"),
                      line_of(p.first));
    }
  } else {
    fail(Code::BAD_STRUCTURE, file, value, "unknown node key '" + key + "'");
  }
}

void parse_nodes(const YAML::Node& nodes, GraphSpec& spec) {
  if (!nodes || !nodes.IsSequence())
    fail(Code::BAD_STRUCTURE, spec.file, nodes, "'nodes' must be a list");
  std::set<std::string> names;
  for (const auto& item : nodes) {
    if (!item.IsMap()) fail(Code::BAD_STRUCTURE, spec.file, item, "each node must be a map");
    NodeSpec node;
    node.line = line_of(item);
    for (const auto& kv : item) parse_node_key(kv.first.Scalar(), kv.second, node, spec.file);
    if (node.name.empty() || node.kind.empty()) {
      fail(Code::BAD_STRUCTURE, spec.file, item, "a node needs both 'name' and 'kind'");
    }
    if (!names.insert(node.name).second) {
      fail(Code::DUPLICATE_NODE, spec.file, item, "node name '" + node.name + "' is used twice");
    }
    spec.nodes.push_back(std::move(node));
  }
}

bool is_name(const std::string& text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
  });
}

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  const auto last = text.find_last_not_of(" \t");
  return first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
}

// Splits "node.port" into its two names; false if either is not a plain identifier.
bool split_endpoint(const std::string& text, std::string& node, std::string& port) {
  const std::string endpoint = trim(text);
  const auto dot = endpoint.find('.');
  if (dot == std::string::npos) return false;
  node = endpoint.substr(0, dot);
  port = endpoint.substr(dot + 1);
  return is_name(node) && is_name(port);
}

// Edges are written "from.port -> to.port" (no std::regex: GCC 12 warns inside it under ASan).
void parse_edges(const YAML::Node& edges, GraphSpec& spec) {
  if (!edges) return;
  if (!edges.IsSequence()) fail(Code::BAD_STRUCTURE, spec.file, edges, "'edges' must be a list");
  for (const auto& item : edges) {
    const std::string text = scalar(item, spec.file, "edge");
    EdgeSpec edge;
    edge.line = line_of(item);
    const auto arrow = text.find("->");
    if (arrow == std::string::npos ||
        !split_endpoint(text.substr(0, arrow), edge.from_node, edge.from_port) ||
        !split_endpoint(text.substr(arrow + 2), edge.to_node, edge.to_port)) {
      fail(Code::BAD_STRUCTURE, spec.file, item,
           "edge '" + text + "' is not of the form 'node.port -> node.port'");
    }
    spec.edges.push_back(std::move(edge));
  }
}

}  // namespace

Result<GraphSpec, GraphError> parse_graph(const std::string& text, const std::string& file) {
  GraphSpec spec;
  spec.file = file;
  try {
    const YAML::Node root = YAML::Load(text);
    if (auto unique = core::check_unique_keys(root); !unique)
      throw Fail{GraphError{Code::BAD_STRUCTURE, file, unique.error().line, unique.error().what}};
    if (!root.IsMap())
      fail(Code::BAD_STRUCTURE, file, root, "a graph file must be a map with 'nodes' and 'edges'");
    for (const auto& item : root) {
      const std::string key = item.first.Scalar();
      if (key != "graph" && key != "nodes" && key != "edges") {
        fail(Code::BAD_STRUCTURE, file, item.first, "unknown top-level key '" + key + "'");
      }
    }
    parse_header(root["graph"], spec);
    parse_nodes(root["nodes"], spec);
    parse_edges(root["edges"], spec);
  } catch (const Fail& f) { return err(f.error); } catch (const YAML::Exception& e) {
    return err(GraphError{Code::SYNTAX, file, e.mark.line >= 0 ? e.mark.line + 1 : 0, e.msg});
  }
  return spec;
}

Result<GraphSpec, GraphError> load_graph_file(const std::string& path) {
  // A regular file of at most 16 MiB, opened without blocking (a FIFO is refused, never waited on).
  auto text = core::read_regular_text(path, std::size_t{16} << 20);
  if (!text)
    return err(
        GraphError{Code::FILE_UNREADABLE, path, 0,
                   "cannot read the graph file: " + text.error().message.substr(path.size() + 2)});
  return parse_graph(*text, path);
}

}  // namespace orthoflow::engine
