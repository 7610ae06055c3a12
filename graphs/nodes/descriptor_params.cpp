#include "graphs/nodes/descriptor_params.hpp"

#include <algorithm>
#include <cstdio>

#include "graphs/frame/frame_block.hpp"
#include "graphs/nodes/node_support.hpp"
#include "learning/dictionary.hpp"

namespace orthoflow::graphs {

namespace {

const std::vector<std::string> KINDS = {"good", "spin", "bow", "lda", "local-lda"};

// descriptor spin: the set's parameters (defaults: kernels::SpinSetParams, the thesis's sets).
kernels::SpinSetParams parse_spin_set(const engine::ParamMap& params, std::string& e) {
  kernels::SpinSetParams p;
  kernels::SpinFeatureParams& f = p.features;
  take(params.integer("spin_keypoints", p.max_keypoints, 1, kernels::MAX_SET_KEYPOINTS),
       p.max_keypoints, e);
  take(params.integer("spin_width", f.spin.image_width, 1, kernels::MAX_SPIN_IMAGE_WIDTH),
       f.spin.image_width, e);
  take(params.number("spin_support", f.spin.support_length, 0.001, 1.0), f.spin.support_length, e);
  take(params.number("spin_leaf", f.keypoint_leaf, 0.001, 1.0), f.keypoint_leaf, e);
  return p;
}

std::string exact(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);  // a float's every digit: parses back equal
  return text;
}

}  // namespace

void assign_spin_set(engine::ParamMap& params, const kernels::SpinSetParams& set) {
  params.assign("spin_keypoints", std::to_string(set.max_keypoints));
  params.assign("spin_width", std::to_string(set.features.spin.image_width));
  params.assign("spin_support", exact(set.features.spin.support_length));
  params.assign("spin_leaf", exact(set.features.keypoint_leaf));
}

void fit_pool_to_descriptors(engine::GraphSpec& graph) {
  const std::size_t frames = FrameBlock::capacity_for(graph.block_bytes);
  graph.block_bytes =
      std::max(graph.block_bytes, FrameBlock::bytes_for(frames, descriptor_room(&graph)));
}

Result<kernels::DescriptorSpec, std::string> parse_describe_params(const engine::ParamMap& params) {
  if (auto ok = params.only({"descriptor", "bins", "mode", "threshold", "dictionary",
                             "max_object_points", "local_topics", "spin_keypoints", "spin_width",
                             "spin_support", "spin_leaf"});
      !ok)
    return err(ok.error());
  kernels::DescriptorSpec spec;  // thesis: GOOD, 15 bins; invariant frame by default (docs/GOOD.md)
  std::string e, kind = "good", mode = "invariant", dictionary;
  take(params.choice("descriptor", "good", KINDS), kind, e);
  if (kind == "spin") {
    const kernels::SpinSetParams set = parse_spin_set(params, e);
    if (!e.empty()) return err(e);
    spec = kernels::DescriptorSpec::make_spin_set(set);
    if (auto valid = spec.validate(); !valid) return err("describe: " + valid.error());
    return spec;  // sized by the block: make_describe checks the frame block's room
  }
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

std::size_t descriptor_room(const engine::GraphSpec* graph) noexcept {
  if (graph == nullptr) return MAX_DESCRIPTOR;
  try {  // start-up only; a describe node with bad parameters reports them itself
    for (const engine::NodeSpec& node : graph->nodes) {
      if (node.kind != "describe") continue;
      std::string e, kind;
      take(node.params.choice("descriptor", "good", KINDS), kind, e);
      if (kind != "spin") return MAX_DESCRIPTOR;
      const kernels::SpinSetParams set = parse_spin_set(node.params, e);
      return e.empty() && set.valid() ? descriptor_room_for(set.length()) : MAX_DESCRIPTOR;
    }
  } catch (...) {  // NOLINT(bugprone-empty-catch): the describe node reports the failure
  }
  return MAX_DESCRIPTOR;
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
