// `orthoflow run`, the graph it runs: how the run's options edit the graph (its source, the
// objects and frames publishers, the describe node's representation) and make the learning
// service's settings. The options and the run loop are in cmd_run.cpp.
#include <algorithm>
#include <string>

#include "apps/graph_overrides.hpp"
#include "apps/run_cli.hpp"
#include "engine/frame_payload.hpp"
#include "engine/object_list_payload.hpp"
#include "graphs/frame/frame_block.hpp"
#include "graphs/nodes/descriptor_params.hpp"
#include "graphs/services/learning_ipc_bridge.hpp"

namespace orthoflow::apps::run_cli {

// Applies --source and --frames to the graph's source node (apps/graph_overrides.hpp).
void override_source(engine::GraphSpec& spec, const RunOptions& o) {
  if (auto ok = apply_source(spec, o.source, o.frames); !ok) fail(ok.error(), EXIT_USAGE);
}

// --publish-objects: an ipc_publish node on the objects_output node's objects port, topic
// orthoflow/<graph>/objects (the graph then needs a running RouDi, like every IPC graph).
void add_objects_publisher(engine::GraphSpec& spec) {
  const auto output =
      std::find_if(spec.nodes.begin(), spec.nodes.end(),
                   [](const engine::NodeSpec& n) { return n.kind == "objects_output"; });
  if (output == spec.nodes.end())
    fail("--publish-objects needs a graph with an objects_output node", EXIT_USAGE);
  engine::NodeSpec publish;
  publish.name = "publish_objects";
  publish.kind = "ipc_publish";
  const auto topics = graphs::graph_topics(spec.name);
  if (!topics)
    fail("--publish-objects: graph name '" + spec.name + "': " + topics.error(), EXIT_USAGE);
  publish.params.assign("topic", topics->objects.str());
  publish.params.assign("type", "objects");
  publish.params.assign("max_bytes", std::to_string(sizeof(engine::ObjectListPayload)));
  spec.edges.push_back(engine::EdgeSpec{output->name, "objects", publish.name, "in", 0});
  spec.nodes.push_back(std::move(publish));
}

// --publish-frames: an ipc_publish node on the objects_output node's out port (each frame as it
// leaves the graph, with its objects decided), topic orthoflow/<graph>/frames: what `orthoflow
// bridge dds --frames` reads. RouDi needs a pool of the graph's block size
// (config/roudi_frames.toml).
void add_frames_publisher(engine::GraphSpec& spec) {
  const auto output =
      std::find_if(spec.nodes.begin(), spec.nodes.end(),
                   [](const engine::NodeSpec& n) { return n.kind == "objects_output"; });
  if (output == spec.nodes.end())
    fail("--publish-frames needs a graph with an objects_output node", EXIT_USAGE);
  const auto topics = graphs::graph_topics(spec.name);
  if (!topics)
    fail("--publish-frames: graph name '" + spec.name + "': " + topics.error(), EXIT_USAGE);
  engine::NodeSpec publish;
  publish.name = "publish_frames";
  publish.kind = "ipc_publish";
  publish.params.assign("topic", topics->frames.str());
  publish.params.assign("type", "frame");
  // The largest frame the blocks hold (every optional field), not the whole block: the block's
  // results, a set of spin images' 19,600 floats per object among them, never leave the process.
  const std::size_t capacity =
      graphs::FrameBlock::capacity_for(spec.block_bytes, graphs::descriptor_room(&spec));
  publish.params.assign("max_bytes", std::to_string(engine::frame_payload_bytes(
                                         static_cast<std::uint32_t>(capacity), 1,
                                         engine::FRAME_FIELD_RGB | engine::FRAME_FIELD_LABEL)));
  spec.edges.push_back(engine::EdgeSpec{output->name, "out", publish.name, "in", 0});
  spec.nodes.push_back(std::move(publish));
}

// --representation and --dictionary: the describe node's descriptor (docs/SPIN_IMAGES.md). A set
// of spin images needs more room per object than the graph's blocks have: the pool grows to hold
// the frames it held before and the sets.
void choose_representation(engine::GraphSpec& spec, const RunOptions& o) {
  const std::string kind =
      o.representation.empty() ? (o.dictionary.empty() ? "" : "bow") : o.representation;
  if (kind != "spin" && !(o.spin == kernels::SpinSetParams{}))
    fail("--spin-* set the spin images of --representation spin only", EXIT_USAGE);
  if (kind.empty() || kind == "good") {
    if (!o.dictionary.empty()) fail("--dictionary: GOOD has no dictionary", EXIT_USAGE);
    if (kind.empty()) return;  // the graph's own describe node
  }
  const bool words = kind == "bow" || kind == "lda" || kind == "local-lda";
  if (words && o.dictionary.empty())
    fail("--representation " + kind + " needs --dictionary FILE", EXIT_USAGE);
  if (!words && !o.dictionary.empty())
    fail("--representation " + kind + " has no dictionary (drop --dictionary)", EXIT_USAGE);
  bool found = false;
  for (engine::NodeSpec& node : spec.nodes) {
    if (node.kind != "describe") continue;
    engine::ParamMap params;  // the graph's GOOD parameters stay for good; others start afresh
    if (kind == "good") params = node.params;
    params.assign("descriptor", kind);
    if (words) params.assign("dictionary", o.dictionary);
    if (kind == "spin") graphs::assign_spin_set(params, o.spin);
    if (node.params.has("max_object_points"))
      params.assign("max_object_points", *node.params.text("max_object_points", ""));
    node.params = std::move(params);
    found = true;
  }
  if (!found) fail("--representation: the graph has no describe node", EXIT_USAGE);
  graphs::fit_pool_to_descriptors(spec);
}

graphs::LearningSettings learning_settings(const engine::GraphSpec& spec, const RunOptions& o) {
  graphs::LearningSettings settings;
  // The learner reads descriptors of the describe node's specification (and a store must have it
  // too).
  auto descriptor = graphs::descriptor_of_graph(spec);
  if (!descriptor) fail(descriptor.error(), EXIT_BAD_INPUT);
  settings.memory.descriptor = *descriptor;
  settings.memory.learner =
      o.learner == "bayes" ? learning::LearnerKind::BAYES : learning::LearnerKind::INSTANCE;
  settings.memory.instance.classification_threshold =
      o.ct.value_or(o.approach == "nn" ? graphs::default_nn_threshold(*descriptor)
                                       : graphs::DEFAULT_NN_THRESHOLD);
  settings.memory.instance.normalise = o.approach != "nn";
  settings.memory.instance.approach = o.approach == "2" ? learning::NocdApproach::MEAN_DISTANCE
                                                        : learning::NocdApproach::MIN_DISTANCE;
  if (!o.db.empty()) settings.db = o.db;
  return settings;
}

}  // namespace orthoflow::apps::run_cli
