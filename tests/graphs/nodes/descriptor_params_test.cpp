// The describe node's parameters: a set of spin images in the graph (parsed, written back equal),
// the descriptor room every node sizes the frame block with, and the pool that grows to hold it.
#include "graphs/nodes/descriptor_params.hpp"

#include <gtest/gtest.h>

#include <string>

#include "engine/graph.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/frame/frame_block.hpp"
#include "graphs/services/learning_service.hpp"
#include "graphs/services/session_log.hpp"
#include "graphs/tabletop.hpp"

namespace orthoflow::graphs {
namespace {

engine::GraphSpec embedded() {
  auto spec = engine::parse_graph(std::string(embedded_tabletop_yaml()), "embedded");
  EXPECT_TRUE(spec) << engine::to_string(spec.error());
  return *spec;
}

engine::ParamMap& describe_params(engine::GraphSpec& spec) {
  for (auto& node : spec.nodes) {
    if (node.kind == "describe") return node.params;
  }
  ADD_FAILURE() << "no describe node";
  return spec.nodes.front().params;
}

TEST(DescribeParams, ASetOfSpinImagesIsParsedAndWrittenBackEqual) {
  engine::ParamMap params;
  params.assign("descriptor", "spin");
  auto defaults = parse_describe_params(params);
  ASSERT_TRUE(defaults) << defaults.error();
  EXPECT_EQ(*defaults, kernels::DescriptorSpec::make_spin_set());  // the thesis's sets
  kernels::SpinSetParams set;
  set.max_keypoints = 40;
  set.features.spin.image_width = 5;
  set.features.spin.support_length = 0.0712F;  // not a round number: every digit must survive
  set.features.keypoint_leaf = 0.0137F;
  assign_spin_set(params, set);
  auto parsed = parse_describe_params(params);
  ASSERT_TRUE(parsed) << parsed.error();
  EXPECT_EQ(*parsed, kernels::DescriptorSpec::make_spin_set(set));
  EXPECT_EQ(parsed->length(), 1 + 40 * kernels::spin_image_bins(5));
  params.assign("spin_width", "17");  // past MAX_SPIN_IMAGE_WIDTH
  EXPECT_FALSE(parse_describe_params(params));
  params.assign("spin_width", "4");
  params.assign("spin_radius", "0.1");  // not a parameter of describe
  auto unknown = parse_describe_params(params);
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().find("spin_radius"), std::string::npos) << unknown.error();
}

TEST(DescribeParams, EveryNodeSizesTheBlockForTheDescribeNodesRoom) {
  EXPECT_EQ(descriptor_room(nullptr), MAX_DESCRIPTOR);
  auto spec = embedded();
  EXPECT_EQ(descriptor_room(&spec), MAX_DESCRIPTOR);  // GOOD, 15 bins
  engine::ParamMap& params = describe_params(spec);
  params = {};
  params.assign("descriptor", "spin");
  const std::size_t set = kernels::SpinSetParams{}.length();
  EXPECT_EQ(descriptor_room(&spec), descriptor_room_for(set));
  params.assign("spin_keypoints", "4");  // a set smaller than GOOD's room still gets that room
  EXPECT_EQ(descriptor_room(&spec), MAX_DESCRIPTOR);
  params.assign("spin_keypoints", "0");  // refused by the describe node: no room of its own
  EXPECT_EQ(descriptor_room(&spec), MAX_DESCRIPTOR);
}

TEST(DescribeParams, ThePoolGrowsToHoldTheFramesAndTheSets) {
  auto spec = embedded();
  const std::size_t before = spec.block_bytes;
  fit_pool_to_descriptors(spec);
  EXPECT_EQ(spec.block_bytes, before) << "GOOD fits the graph's blocks";
  describe_params(spec) = {};
  describe_params(spec).assign("descriptor", "spin");
  const std::size_t room = descriptor_room(&spec);
  EXPECT_LT(FrameBlock::capacity_for(spec.block_bytes, room), 640U * 480U);
  fit_pool_to_descriptors(spec);
  EXPECT_GT(spec.block_bytes, before);
  EXPECT_GE(FrameBlock::capacity_for(spec.block_bytes, room), 640U * 480U);
  EXPECT_EQ(FrameBlock::capacity_for(spec.block_bytes, room), FrameBlock::capacity_for(before))
      << "the same frames as before";
}

TEST(DescribeParams, AGraphWhoseBlocksCannotHoldTheSetsIsRefusedWithTheBytesItNeeds) {
  auto spec = embedded();
  describe_params(spec) = {};
  describe_params(spec).assign("descriptor", "spin");
  auto learning = LearningService::open({});
  ASSERT_TRUE(learning) << learning.error();
  auto json = LineWriter::open("/dev/null");
  ASSERT_TRUE(json);
  SessionLog log(std::move(*json));
  const auto registry = make_tabletop_registry(**learning, log);
  auto refused = engine::build_graph(spec, registry);
  ASSERT_FALSE(refused);
  const std::string message = engine::to_string(refused.error());
  EXPECT_NE(message.find("raise pool block_bytes to"), std::string::npos) << message;
  fit_pool_to_descriptors(spec);
  auto built = engine::build_graph(spec, registry, engine::BuildMode::CHECK);
  EXPECT_TRUE(built) << engine::to_string(built.error());
}

}  // namespace
}  // namespace orthoflow::graphs
