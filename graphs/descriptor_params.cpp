#include "graphs/descriptor_params.hpp"

#include "graphs/frame_block.hpp"
#include "graphs/node_support.hpp"

namespace orthoflow::graphs {

Result<kernels::DescriptorSpec, std::string> parse_describe_params(const engine::ParamMap& params) {
  if (auto ok = params.only({"descriptor", "bins", "mode", "threshold"}); !ok)
    return err(ok.error());
  kernels::DescriptorSpec spec;  // thesis: GOOD, 15 bins; invariant frame by default (docs/GOOD.md)
  std::string e, kind = "good", mode = "invariant";
  take(params.choice("descriptor", "good", {"good"}), kind, e);
  take(params.integer("bins", 15, 1, MAX_GOOD_BINS), spec.good.bins, e);
  take(params.choice("mode", "invariant", {"invariant", "reference"}), mode, e);
  if (params.has("threshold")) {
    float t = 0.0F;
    if (take(params.number("threshold", 0.0, 0.0, 1.0), t, e)) spec.good.threshold = t;
  }
  if (!e.empty()) return err(e);
  spec.good.mode =
      mode == "invariant" ? kernels::GoodMode::INVARIANT : kernels::GoodMode::REFERENCE;
  if (spec.length() > MAX_DESCRIPTOR)
    return err("describe: " + spec.describe() + " does not fit the frame block");
  return spec;
}

Result<kernels::DescriptorSpec, std::string> descriptor_of_graph(const engine::GraphSpec& spec) {
  const engine::NodeSpec* found = nullptr;
  for (const engine::NodeSpec& node : spec.nodes) {
    if (node.kind != "describe") continue;
    if (found != nullptr)
      return err("graph '" + spec.name + "': more than one describe node ('" + node.name + "')");
    found = &node;
  }
  if (found == nullptr) return kernels::DescriptorSpec{};
  auto parsed = parse_describe_params(found->params);
  if (!parsed) return err("node '" + found->name + "': " + parsed.error());
  return parsed;
}

}  // namespace orthoflow::graphs
