#include "graphs/descriptor_params.hpp"

#include "graphs/frame_block.hpp"
#include "graphs/node_support.hpp"
#include "learning/dictionary.hpp"

namespace orthoflow::graphs {

Result<kernels::DescriptorSpec, std::string> parse_describe_params(const engine::ParamMap& params) {
  if (auto ok = params.only({"descriptor", "bins", "mode", "threshold", "dictionary",
                             "max_object_points", "local_topics"});
      !ok)
    return err(ok.error());
  kernels::DescriptorSpec spec;  // thesis: GOOD, 15 bins; invariant frame by default (docs/GOOD.md)
  std::string e, kind = "good", mode = "invariant", dictionary;
  take(params.choice("descriptor", "good", {"good", "bow", "lda", "local-lda"}), kind, e);
  if (kind != "good") take(params.text("dictionary", ""), dictionary, e);
  if (kind == "local-lda")
    take(params.integer("local_topics", 30, 1, kernels::MAX_LOCAL_TOPICS), spec.local_topics.topics,
         e);
  take(params.integer("bins", 15, 1, MAX_GOOD_BINS), spec.good.bins, e);
  take(params.choice("mode", "invariant", {"invariant", "reference"}), mode, e);
  if (params.has("threshold")) {
    float t = 0.0F;
    if (take(params.number("threshold", 0.0, 0.0, 1.0), t, e)) spec.good.threshold = t;
  }
  if (!e.empty()) return err(e);
  spec.good.mode =
      mode == "invariant" ? kernels::GoodMode::INVARIANT : kernels::GoodMode::REFERENCE;
  if (kind != "good") {  // over a dictionary file (docs/SPIN_IMAGES.md)
    if (dictionary.empty())
      return err("describe: descriptor " + kind + " needs a dictionary file (dictionary: ...)");
    auto words = learning::load_dictionary(dictionary);
    if (!words) return err("describe: " + words.error());
    spec.kind = kernels::descriptor_kind(kind).value_or(kernels::DescriptorKind::BOW);
    spec.dictionary = std::make_shared<const kernels::VisualDictionary>(std::move(words.value()));
    if (auto valid = spec.validate(); !valid) return err("describe: " + valid.error());
  }
  if (spec.length() > MAX_DESCRIPTOR)
    return err("describe: " + spec.describe() + " does not fit the frame block");
  return spec;
}

Result<std::size_t, std::string> parse_max_object_points(const engine::ParamMap& params) {
  std::size_t n = 20000;
  std::string e;
  take(params.integer("max_object_points", 20000, 100, 1000000), n, e);
  if (!e.empty()) return err(e);
  return n;
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
