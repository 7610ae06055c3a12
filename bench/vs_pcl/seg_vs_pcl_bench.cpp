// Ours vs PCL 1.13, same frames, same parameters, same run: each stage and the whole tabletop chain
// on the shared mOSD frames and on synthetic scenes with 3, 10 and 30 objects. 3 warm-up runs, then
// ROUNDS rounds alternating ours and PCL; prints medians (ms), ratios PCL/ours and detection
// quality (tests/kernels/seg_quality.hpp rule). Usage: seg_vs_pcl_bench [ROUNDS]. Single-threaded.
// The mOSD frames run twice: the default chain (strided pixel sample for the plane) and
// organized_stride = 0 (the voxel grid of every kept pixel, as before).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/vs_pcl/pcl_chain.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/segmentation_chain.hpp"
#include "simulation/world/synthetic_scene.hpp"
#include "tests/kernels/seg_quality.hpp"

namespace ob = orthoflow::bench;
namespace ok = orthoflow::kernels;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Input {
  std::string name;
  ok::PointCloud cloud;
  std::vector<std::uint32_t> gt;  // mOSD-style labels (object k >= 2 as 10k)
};

void run_input(const Input& in, int rounds, const ok::SegmentationParams& params = {},
               const char* suffix = "") {
  const auto pcl_cloud = ob::to_pcl(in.cloud);
  ok::SegmentationChain chain(in.cloud.size(), params);
  std::vector<std::vector<double>> ours(6), theirs(6);
  ob::PclResult pcl_last;
  std::vector<std::int32_t> our_labels;
  for (int r = -3; r < rounds; ++r) {
    auto seg = chain.run(in.cloud.view());
    if (!seg) {
      std::printf("%s: ours failed: %s\n", in.name.c_str(), seg.error().to_string().c_str());
      return;
    }
    pcl_last = ob::run_pcl_chain(pcl_cloud);
    if (r < 0) { continue; }
    const auto& t = seg->timings;
    const double o[6] = {t.filter, t.voxel, t.plane, t.prism, t.cluster, t.total};
    const double p[6] = {pcl_last.t.filter,
                         pcl_last.t.voxel,
                         pcl_last.t.plane,
                         pcl_last.t.prism,
                         pcl_last.t.cluster + pcl_last.t.pca,
                         pcl_last.t.total};
    for (int s = 0; s < 6; ++s) { ours[s].push_back(o[s]), theirs[s].push_back(p[s]); }
    if (r == rounds - 1) { our_labels.assign(seg->labels.begin(), seg->labels.end()); }
  }
  const char* stages[6] = {"filter", "voxel", "plane", "hull+prism", "cluster+stats", "total"};
  std::printf("| %s%s |", in.name.c_str(), suffix);
  for (int s = 0; s < 6; ++s) {
    if (median(ours[s]) ==
        0.0) {  // a stage our chain does not run (the voxel grid on the strided path)
      std::printf(" not run / %.2f |", median(theirs[s]));
      continue;
    }
    std::printf(" %.2f / %.2f = %.1fx |", median(ours[s]), median(theirs[s]),
                median(theirs[s]) / median(ours[s]));
  }
  const auto q_ours = orthoflow::testing::evaluate(in.gt, our_labels);
  const auto q_pcl =
      orthoflow::testing::evaluate(in.gt, ob::pcl_pixel_labels(in.cloud, pcl_last, 0.005F));
  std::printf(
      " %zu | ours %zu cl, %zu matched (P %.2f R %.2f, over %zu under %zu) | PCL %zu cl, %zu "
      "matched (P %.2f R %.2f, over %zu under %zu) |\n",
      q_ours.gt_objects, q_ours.clusters, q_ours.matched, q_ours.precision(), q_ours.recall(),
      q_ours.over, q_ours.under, q_pcl.clusters, q_pcl.matched, q_pcl.precision(), q_pcl.recall(),
      q_pcl.over, q_pcl.under);
  (void)stages;
}

Input synthetic(std::uint32_t objects, std::uint64_t seed) {
  orthoflow::simulation::SceneConfig config;
  config.objects = objects;
  const auto scene = orthoflow::simulation::make_scene(config, seed);
  orthoflow::core::Rng rng(seed);
  Input in{"synthetic " + std::to_string(scene.objects.size()) + " objects", ok::PointCloud{}, {}};
  orthoflow::simulation::render_scene(scene, {}, rng, in.cloud);
  for (const std::uint32_t l : in.cloud.label()) {
    const int obj = orthoflow::simulation::object_of_label(l);
    in.gt.push_back(obj >= 0 ? static_cast<std::uint32_t>(obj + 2) * 10U : 0U);
  }
  return in;
}

}  // namespace

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::max(1, std::atoi(argv[1])) : 30;
  std::printf(
      "| input | filter ours / PCL = ratio | voxel | plane | hull+prism | cluster+stats | total | "
      "gt objects | ours | PCL |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const char* f : {"test31.pcd", "test44.pcd", "test55.pcd"}) {
    auto cloud_result =
        orthoflow::formats::read_pcd(std::string(ORTHOFLOW_SHARED_DIR) + "/data/scenes/" + f);
    if (!cloud_result) {
      std::printf("%s: %s\n", f, cloud_result.error().to_string().c_str());
      return 1;
    }
    Input in{std::string("mOSD ") + f, std::move(*cloud_result), {}};
    in.gt.assign(in.cloud.label().begin(), in.cloud.label().end());
    run_input(in, rounds);
    ok::SegmentationParams voxel_params;  // the organized chain with the voxel grid as plane input
    voxel_params.organized_stride = 0;
    run_input(in, rounds, voxel_params, " (stride 0: voxel grid)");
  }
  for (const std::uint32_t n : {3U, 10U, 30U}) { run_input(synthetic(n, 1000U + n), rounds); }
  return 0;
}
