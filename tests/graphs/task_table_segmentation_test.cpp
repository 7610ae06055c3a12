// The tables of `orthoflow demo` (draw_task_table, seeds 1-10) through the product's segmentation
// (the embedded tabletop graph's chain): every object taller than a plate is one segment of its
// own. Two cans of one height that touch (seed 4) meet at their tops, where no crease parts them;
// the neck split (kernels/neck_split.cpp) cuts them, and nothing else on these tables. A warm chain
// cuts them without allocating. (Renders 640x480 frames: qemu_heavy.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "engine/graph.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/segment_params.hpp"
#include "graphs/sessions/table_task_session.hpp"
#include "kernels/frame_labels.hpp"
#include "kernels/segmentation_chain.hpp"
#include "simulation/world/synthetic_scene.hpp"
#include "tests/support/counting_new.hpp"  // the one TU of this binary that replaces operator new

namespace orthoflow::graphs {
namespace {

TabletopSegmentation tabletop() {
  auto spec = engine::parse_graph(std::string(embedded_tabletop_yaml()), "tabletop.yaml");
  EXPECT_TRUE(spec);
  auto seg = segmentation_of_graph(*spec);
  EXPECT_TRUE(seg);
  return *seg;
}

kernels::PointCloud render_table(const simulation::Scene& scene, std::uint64_t seed) {
  core::Rng rng(seed);
  kernels::PointCloud cloud;
  simulation::render_scene(scene, {}, rng, cloud);
  return cloud;
}

/// Per object of the scene but plates: the segment holding most of its object pixels,
/// and that segment's share of them; objects sharing one segment are reported.
struct ObjectSegments {
  std::map<int, std::pair<std::int32_t, double>> best;  // object -> (segment, share)
  std::size_t shared = 0;                               // objects whose segment another holds
};

ObjectSegments segments_of(const kernels::PointCloud& cloud, const simulation::Scene& scene,
                           const TabletopSegmentation& seg) {
  kernels::SegmentationChain chain(cloud.size(), seg.stages, seg.candidates);
  auto result = chain.run(cloud.view());
  EXPECT_TRUE(result);
  std::map<int, std::map<std::int32_t, std::size_t>> hist;
  std::map<int, std::size_t> total;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int object = simulation::object_of_label(cloud.label()[i]);
    const std::int32_t c = result->labels[i];
    if (object < 0 || c < 0 || result->candidate_of[static_cast<std::size_t>(c)] < 0) continue;
    ++hist[object][result->candidate_of[static_cast<std::size_t>(c)]];
    ++total[object];
  }
  ObjectSegments out;
  std::map<std::int32_t, int> owners;
  for (const auto& [object, h] : hist) {
    if (scene.objects[static_cast<std::size_t>(object)].model.category ==
        simulation::Category::PLATE)
      continue;  // a table item, mostly below the prism's 1 cm
    const auto top = std::max_element(
        h.begin(), h.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    out.best[object] = {top->first, double(top->second) / double(total[object])};
    out.shared += owners[top->first]++ > 0 ? 1 : 0;
  }
  return out;
}

TEST(TaskTableSegmentation, EveryObjectTallerThanAPlateIsOneSegment) {
  // No two objects share a segment; each has 90 % of its object pixels in its segment, but for
  // one: seed 9's mug, whose inside is cut off by its rim (over-segmented, the known case of
  // docs/SEGMENTATION.md), and which the demo still places.
  const TabletopSegmentation seg = tabletop();
  std::size_t objects = 0, whole = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const simulation::Scene scene = draw_task_table(TableTaskConfig{}, seed);
    const ObjectSegments s = segments_of(render_table(scene, seed), scene, seg);
    EXPECT_EQ(s.shared, 0U) << "seed " << seed;
    for (const auto& [object, best] : s.best) {
      ++objects;
      whole += best.second >= 0.9 ? 1 : 0;
      if (best.second < 0.9)
        std::printf("seed %llu object %d: %.2f in one segment\n",
                    static_cast<unsigned long long>(seed), object, best.second);
    }
  }
  EXPECT_EQ(objects, 36U);
  EXPECT_GE(whole, objects - 1);
}

TEST(TaskTableSegmentation, TheNeckSplitPartsTheTwoTouchingCansOfSeed4) {
  TabletopSegmentation seg = tabletop();
  const simulation::Scene scene = draw_task_table(TableTaskConfig{}, 4);
  const kernels::PointCloud cloud = render_table(scene, 4);
  ASSERT_EQ(scene.objects.size(), 5U);
  ASSERT_EQ(scene.objects[2].model.category, simulation::Category::CAN);
  ASSERT_EQ(scene.objects[3].model.category, simulation::Category::CAN);
  const ObjectSegments cut = segments_of(cloud, scene, seg);
  EXPECT_NE(cut.best.at(2).first, cut.best.at(3).first);
  EXPECT_GE(cut.best.at(2).second, 0.95);
  EXPECT_GE(cut.best.at(3).second, 0.95);
  seg.stages.crease.neck_cell = 0.0F;  // the split off: the cans are one segment
  const ObjectSegments whole = segments_of(cloud, scene, seg);
  EXPECT_EQ(whole.best.at(2).first, whole.best.at(3).first);
  EXPECT_EQ(whole.shared, 1U);
}

TEST(TaskTableSegmentation, AWarmChainCutsWithoutAllocating) {
  const TabletopSegmentation seg = tabletop();
  const kernels::PointCloud cloud = render_table(draw_task_table(TableTaskConfig{}, 4), 4);
  kernels::SegmentationChain chain(cloud.size(), seg.stages, seg.candidates);
  ASSERT_TRUE(chain.run(cloud.view()));
  test::g_allocations = 0;
  test::g_counting = true;
  const auto result = chain.run(cloud.view());
  test::g_counting = false;
  ASSERT_TRUE(result);
  EXPECT_EQ(result->candidates.size(), 5U);  // 2 bottles, 3 cans
  EXPECT_EQ(test::g_allocations.load(), 0U);
}

}  // namespace
}  // namespace orthoflow::graphs
