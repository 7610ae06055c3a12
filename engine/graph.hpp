#pragma once
/// @file
/// @brief The declarative graph: GraphSpec (what the YAML file says), GraphError (what is wrong
/// with it, with file and line) and Graph (validated, nodes instantiated, ready for the Engine).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "engine/node.hpp"
#include "engine/params.hpp"
#include "engine/registry.hpp"
#include "memory_pool/block_pool.hpp"

namespace orthoflow::engine {

/// @brief What a node does with a backlog: QUEUE processes every message, LATEST skips any message
/// older than the newest frame that has already reached it (each skip is counted as a drop).
enum class Policy { QUEUE, LATEST };

/// @brief One node as written in the graph file.
struct NodeSpec {
  std::string name;
  std::string kind;
  ParamMap params;
  Policy policy = Policy::QUEUE;
  bool ordered = false;          ///< restore frame order (sequencer keyed by frame id) before it
  std::int64_t deadline_ns = 0;  ///< per-node deadline for its own processing (0 = graph period)
  int line = 0;
};

/// @brief One connection `from_node.from_port -> to_node.to_port`.
struct EdgeSpec {
  std::string from_node, from_port, to_node, to_port;
  int line = 0;
};

/// @brief A whole graph file.
struct GraphSpec {
  std::string file;  ///< for error messages
  std::string name = "graph";
  std::int64_t period_ns = 0;      ///< expected frame period: deadline for each frame (0 = none)
  std::size_t block_bytes = 4096;  ///< frame pool: bytes per block
  std::size_t blocks = 8;          ///< frame pool: number of blocks
  std::size_t max_in_flight = 0;   ///< frames in flight (limiter); 0 = blocks
  int pool_line = 0;               ///< line of the pool entry in the graph file (0 if none)
  std::vector<NodeSpec> nodes;
  std::vector<EdgeSpec> edges;
};

/// @brief A graph file problem, located by file and 1-based line.
struct GraphError {
  enum class Code {
    FILE_UNREADABLE,
    SYNTAX,
    BAD_STRUCTURE,
    DUPLICATE_NODE,
    UNKNOWN_KIND,
    UNKNOWN_NODE,
    UNKNOWN_PORT,
    TYPE_MISMATCH,
    UNCONNECTED_INPUT,
    CYCLE,
    BAD_PARAMETER,
    SOURCE_COUNT,
    POOL
  };
  Code code = Code::SYNTAX;
  std::string file;
  int line = 0;
  std::string message;
};

/// @brief Name of a code, e.g. "UNKNOWN_PORT".
[[nodiscard]] std::string to_string(GraphError::Code code);
/// @brief "file:line: error [CODE]: message".
[[nodiscard]] std::string to_string(const GraphError& error);

/// @brief Parses graph YAML text; `file` only labels errors. Start-up only (may allocate freely).
[[nodiscard]] Result<GraphSpec, GraphError> parse_graph(const std::string& text,
                                                        const std::string& file);
/// @brief Reads and parses a graph file.
[[nodiscard]] Result<GraphSpec, GraphError> load_graph_file(const std::string& path);

/// @brief A resolved connection between node and port indices.
struct Edge {
  std::size_t from_node = 0, from_port = 0, to_node = 0, to_port = 0;
};

/// @brief A validated graph: pool carved, nodes built, edges resolved. Not movable (nodes keep
/// pointers to the pool and to their names).
struct Graph {
  Graph() = default;
  Graph(const Graph&) = delete;
  Graph& operator=(const Graph&) = delete;
  GraphSpec spec;
  std::unique_ptr<memory_pool::BlockPool> pool;  // declared before nodes: destroyed after them
  std::vector<std::unique_ptr<Node>> nodes;      // same order as spec.nodes
  std::vector<Edge> edges;
  std::vector<std::size_t> topo_order;  // sources first
  std::size_t source = 0;
  std::size_t max_in_flight = 1;
  BuildMode mode = BuildMode::RUN;  // CHECK: validated only; the Engine refuses it
};

/// @brief Validates `spec` against `registry` and instantiates it: unknown kind/node/port, type
/// mismatch, unconnected required input, cycle, bad parameter, source count and pool errors.
/// @param mode RUN (default): ready for the Engine; IPC kinds register with RouDi here. CHECK: the
/// same checks and errors, but no node connects to anything outside this process (no RouDi needed);
/// the result can be inspected and drawn, not run.
[[nodiscard]] Result<std::unique_ptr<Graph>, GraphError> build_graph(
    const GraphSpec& spec, const NodeRegistry& registry, BuildMode mode = BuildMode::RUN);

/// @brief Graphviz text of a validated graph (ports as edge labels, policies as node labels).
[[nodiscard]] std::string to_dot(const Graph& graph);

}  // namespace orthoflow::engine
