// A user's program that runs a graph on the installed engine (oneTBB, yaml-cpp; iceoryx through the
// IPC error names) and links every orthoflow library.
#include <cstdio>
#include <string>

#include "engine/engine.hpp"
#include "engine/graph.hpp"
#include "engine/ipc_runtime.hpp"
#include "engine/registry.hpp"

int main() {
  namespace engine = orthoflow::engine;
  engine::NodeRegistry registry;
  engine::add_generic_nodes(registry);
  auto spec = engine::parse_graph(
      "graph:\n  name: consumer\nnodes:\n"
      "  - {name: src, kind: ticker, params: {frames: 3}}\n"
      "  - {name: sink, kind: count}\nedges:\n  - src.out -> sink.in\n",
      "consumer.yaml");
  if (!spec) return 1;
  auto graph = engine::build_graph(*spec, registry);
  if (!graph) return 1;
  engine::Engine runner(**graph, engine::EngineConfig{1});
  runner.run(engine::RunOptions{});
  const auto done = runner.stats().frames_done.load();
  std::printf("consumer_full: %llu frames through graph 'consumer' (%s known)\n",
              static_cast<unsigned long long>(done),
              std::string(engine::to_string(engine::IpcError::Code::ROUDI_UNREACHABLE)).c_str());
  return done == 3 ? 0 : 1;
}
