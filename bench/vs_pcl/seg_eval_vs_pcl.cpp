// `orthoflow evaluate-segmentation` with PCL's chain as the reference row: the product's chain (the
// embedded tabletop graph's parameters, read from graphs/tabletop.yaml's values via the same
// parser) and PCL 1.13's classic chain (specs/BASELINES.md) scored by the same code
// (evaluation/segmentation_eval.hpp) on the same labelled frames. PCL's objects are all its
// clusters (the baseline has no candidate constraints); its table is the pixels within tau of its
// plane inside the ROI. Usage: seg_eval_vs_pcl DIR [NAMES] [--json]. Bench only: PCL never reaches
// product code.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "bench/vs_pcl/pcl_chain.hpp"
#include "engine/graph.hpp"
#include "evaluation/segmentation_eval.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/segment_params.hpp"
#include "kernels/frame_labels.hpp"

namespace ob = orthoflow::bench;
namespace oe = orthoflow::evaluation;
namespace ok = orthoflow::kernels;

namespace {

oe::SegmenterOutput pcl_segmenter(const ok::PointCloud& cloud) {
  oe::SegmenterOutput out;
  const auto pcl_cloud = ob::to_pcl(cloud);
  const ob::PclResult r = ob::run_pcl_chain(pcl_cloud);
  if (r.plane.values.size() != 4) {
    out.error = "PCL found no plane";
    return out;
  }
  const auto clusters = ob::pcl_pixel_labels(cloud, r, 0.005F);
  ok::Plane plane{{r.plane.values[0], r.plane.values[1], r.plane.values[2]}, r.plane.values[3]};
  const float norm =
      std::sqrt(plane.normal[0] * plane.normal[0] + plane.normal[1] * plane.normal[1] +
                plane.normal[2] * plane.normal[2]);
  for (float& v : plane.normal) v /= norm;
  plane.d /= norm;
  std::vector<std::int32_t> slot_of(r.clusters.size());
  for (std::size_t k = 0; k < slot_of.size(); ++k) slot_of[k] = static_cast<std::int32_t>(k);
  out.labels.resize(cloud.size());
  ok::frame_labels(cloud.points(), plane, 0.02F, ok::SegmentationParams{}.roi, clusters, slot_of,
                   out.labels);
  out.plane = plane;
  out.ms = r.t.total;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: seg_eval_vs_pcl DIR [NAMES] [--json]\n");
    return 2;
  }
  bool json = false;
  std::string names_file;
  for (int i = 2; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0) {
      json = true;
    } else {
      names_file = argv[i];
    }
  }
  auto frames = oe::labelled_frames(argv[1]);
  if (!frames) {
    std::fprintf(stderr, "%s\n", frames.error().to_string().c_str());
    return 2;
  }
  oe::SegEvalOptions options;
  if (!names_file.empty()) {
    auto names = oe::read_frame_names(names_file);
    if (!names) {
      std::fprintf(stderr, "%s\n", names.error().to_string().c_str());
      return 2;
    }
    options.names = *names;
  }
  auto spec = orthoflow::engine::parse_graph(
      std::string(orthoflow::graphs::embedded_tabletop_yaml()), "tabletop.yaml");
  if (!spec) return 2;
  auto seg = orthoflow::graphs::segmentation_of_graph(*spec);
  if (!seg) return 2;
  auto ours = oe::evaluate_segmentation(
      *frames, "orthoflow",
      oe::make_chain_segmenter(seg->stages, seg->candidates, &seg->table.verdict), options);
  auto theirs = oe::evaluate_segmentation(*frames, "PCL 1.13", pcl_segmenter, options);
  if (!ours || !theirs) return 1;
  const std::vector<oe::SegReport> reports{*ours, *theirs};
  std::fputs((json ? oe::segmentation_json(reports) : oe::segmentation_markdown(reports)).c_str(),
             stdout);
  return 0;
}
