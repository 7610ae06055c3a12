// The session_log sink node: hands every frame to the SessionLog it is bound to
// (graphs/services/session_log.hpp), in frame order.
#include "graphs/nodes/session_log_node.hpp"

#include "graphs/nodes/node_support.hpp"

namespace orthoflow::graphs {

namespace {
const engine::PortSpec SINK_IN[] = {FRAME_IN};
}  // namespace

namespace {

class SessionLogNode final : public engine::Node {
 public:
  SessionLogNode(std::size_t capacity, SessionLog& log) : capacity_(capacity), log_(log) {}
  std::span<const engine::PortSpec> inputs() const noexcept override { return SINK_IN; }
  std::span<const engine::PortSpec> outputs() const noexcept override { return {}; }
  bool stateful() const noexcept override { return true; }
  void process(const engine::Message& in, engine::Emitter& /*out*/) noexcept override {
    log_.record(block_of(in, capacity_), in.frame_id);
  }

 private:
  std::size_t capacity_;
  SessionLog& log_;
};

}  // namespace

void add_session_log_node(engine::NodeRegistry& registry, SessionLog& log) {
  registry.add(
      "session_log", "sink: summary, accuracy against ground truth, JSON lines, snapshot",
      [&log](const engine::ParamMap& params, const engine::NodeContext& context) -> NodeResult {
        auto capacity = frame_capacity(context);
        if (!capacity) return err(capacity.error());
        if (auto ok = params.only({}); !ok) return err(ok.error());
        return std::unique_ptr<engine::Node>(new SessionLogNode(*capacity, log));
      });
}

}  // namespace orthoflow::graphs
