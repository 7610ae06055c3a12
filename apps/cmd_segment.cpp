// `orthoflow segment FILE.pcd`: the tabletop chain (kernels/segmentation_chain.hpp) on one frame:
// the table plane, its inlier count, the clusters, the objects (the clusters that pass C_size and
// C_edge: what the tabletop graph tracks) and the per-stage timings (median over --repeat runs).
// Defaults are the PCL baseline's (specs/BASELINES.md); --graph FILE|tabletop takes every
// segmentation parameter from a graph file's preprocess, table and objects nodes instead, so that
// the objects are the ones `orthoflow run` finds with that graph. The flags, applied after --graph,
// mean what the PCL parameters mean: --leaf is VoxelGrid's leaf, --plane-tau/--plane-iters
// SACSegmentation's distance threshold and max iterations, --cluster-tol and --min-cluster
// EuclideanClusterExtraction's tolerance and minimum size. An organized frame fits its plane on a
// strided pixel sample, which has no leaf: --leaf given there replaces the sample by the voxel grid
// of that leaf (organized_stride 0), so that the flag always does what it says. The plane input
// used is printed ("plane input:") and in the JSON ("plane_input").
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "apps/graph_segmentation.hpp"
#include "apps/json_numbers.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/frame_labels.hpp"
#include "kernels/pinhole_regrid.hpp"
#include "kernels/segmentation_chain.hpp"

namespace orthoflow::apps {
namespace {

struct SegmentOptions {
  std::string file;
  bool json = false;
  int repeat = 1;
  std::string graph;       ///< empty: the PCL baseline's parameters
  std::string labels_out;  ///< non-empty: write the frame with our per-point labels here
  /// Put an unorganized camera-frame cloud back on its pixel grid (kernels/pinhole_regrid.hpp) as
  /// the product's pcd_source does: on with --graph unless --keep-unorganized.
  bool keep_unorganized = false;
  kernels::SegmentationParams params{};
  kernels::CandidateParams candidates{};
  // flags given on the command line (applied over the graph's parameters)
  std::optional<float> leaf, plane_tau, cluster_tol;
  std::optional<std::uint32_t> plane_iters, min_cluster;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

nlohmann::json triple(const std::array<float, 3>& a) { return {a[0], a[1], a[2]}; }

/// Median of every stage over the runs.
nlohmann::json median_timings(const std::vector<kernels::SegmentationTimings>& runs) {
  auto stage = [&](double kernels::SegmentationTimings::*field) {
    std::vector<double> v;
    for (const auto& t : runs) { v.push_back(t.*field); }
    return median(v);
  };
  using T = kernels::SegmentationTimings;
  return {{"filter", stage(&T::filter)},   {"voxel", stage(&T::voxel)},
          {"plane", stage(&T::plane)},     {"prism", stage(&T::prism)},
          {"cluster", stage(&T::cluster)}, {"candidates", stage(&T::candidates)},
          {"total", stage(&T::total)}};
}

nlohmann::json stats_json(std::span<const kernels::ClusterStats> list) {
  nlohmann::json out = nlohmann::json::array();
  for (const kernels::ClusterStats& s : list) {
    out.push_back({{"points", s.points},
                   {"centroid", triple(s.centroid)},
                   {"bbox_min", triple(s.bbox_min)},
                   {"bbox_max", triple(s.bbox_max)}});
  }
  return out;
}

/// What the plane was fitted on: the strided pixel sample, the voxel grid or every kept point
/// (kernels/tabletop_stages.hpp, PlaneInputStage).
nlohmann::json plane_input_json(const kernels::PointCloud& cloud,
                                const kernels::SegmentationParams& p) {
  if (kernels::takes_strided_sample(cloud.view(), p)) {
    return {{"kind", "pixel_sample"}, {"stride", p.organized_stride}};
  }
  if (p.leaf > 0.0F) return {{"kind", "voxel_grid"}, {"leaf", floats_json(std::array{p.leaf})[0]}};
  return {{"kind", "every_point"}};
}

nlohmann::json to_json(const kernels::SegmentationResult& seg, const nlohmann::json& timings,
                       const nlohmann::json& plane_input) {
  const kernels::CandidateCounts& c = seg.candidate_counts;
  return {{"plane_input", plane_input},
          {"plane", {{"normal", triple(seg.plane.plane.normal)}, {"d", seg.plane.plane.d}}},
          {"inliers", seg.plane.inliers},
          {"plane_check",
           {{"near_share", floats_json(std::array{seg.plane_check.near_share})[0]},
            {"rms_m", floats_json(std::array{seg.plane_check.rms_m})[0]},
            {"switched", seg.plane_check.switched}}},
          {"clusters", stats_json(seg.clusters)},
          {"objects", stats_json(seg.candidates)},
          {"rejected",
           {{"size", c.rejected_size}, {"edge", c.rejected_edge}, {"capacity", c.over_capacity}}},
          // the work budget: objects' points are those clustered, every stride-th pixel and row
          {"budget", {{"stride", seg.stride}, {"refined", seg.refined}}},
          {"timings_ms", timings}};
}

void print_text(const nlohmann::json& j) {
  const auto& in = j["plane_input"];
  if (in["kind"] == "pixel_sample") {
    std::printf("plane input: pixel sample, stride %u\n", in["stride"].get<unsigned>());
  } else if (in["kind"] == "voxel_grid") {
    std::printf("plane input: voxel grid, leaf %g m\n", in["leaf"].get<double>());
  } else {
    std::printf("plane input: every point inside the region of interest\n");
  }
  if (const auto& g = j["regridded"]; g.is_object() && g.contains("refused")) {
    std::printf("unorganized cloud kept as it is: %s\n", g["refused"].get<std::string>().c_str());
  } else if (g.is_object()) {
    std::printf("unorganized cloud put back on its %ux%u pixel grid (fx %.2f, fy %.2f)\n",
                g["width"].get<unsigned>(), g["height"].get<unsigned>(), g["fx"].get<double>(),
                g["fy"].get<double>());
  }
  const auto& n = j["plane"]["normal"];
  std::printf("plane: normal (%.5f, %.5f, %.5f) d %.5f, %zu inliers\n", n[0].get<double>(),
              n[1].get<double>(), n[2].get<double>(), j["plane"]["d"].get<double>(),
              j["inliers"].get<std::size_t>());
  const auto& check = j["plane_check"];
  std::printf("plane check: %.3f of the sample inliers within 1 cm, RMS %.4f m%s\n",
              check["near_share"].get<double>(), check["rms_m"].get<double>(),
              check["switched"].get<bool>()
                  ? "; the first plane was another level (floor or an object's top): took the table"
                  : "");
  std::printf("clusters: %zu; objects (C_size, C_edge): %zu\n", j["clusters"].size(),
              j["objects"].size());
  for (std::size_t k = 0; k < j["objects"].size(); ++k) {
    const auto& o = j["objects"][k];
    std::printf(
        "  %zu: %zu points, centroid (%.4f, %.4f, %.4f), bbox (%.4f, %.4f, %.4f)..(%.4f, %.4f, "
        "%.4f)\n",
        k, o["points"].get<std::size_t>(), o["centroid"][0].get<double>(),
        o["centroid"][1].get<double>(), o["centroid"][2].get<double>(),
        o["bbox_min"][0].get<double>(), o["bbox_min"][1].get<double>(),
        o["bbox_min"][2].get<double>(), o["bbox_max"][0].get<double>(),
        o["bbox_max"][1].get<double>(), o["bbox_max"][2].get<double>());
  }
  const auto& t = j["timings_ms"];
  std::printf(
      "timings (ms, median): filter %.3f voxel %.3f plane %.3f prism %.3f cluster %.3f candidates "
      "%.3f total %.3f\n",
      t["filter"].get<double>(), t["voxel"].get<double>(), t["plane"].get<double>(),
      t["prism"].get<double>(), t["cluster"].get<double>(), t["candidates"].get<double>(),
      t["total"].get<double>());
}

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow segment: " << message << '\n';
  throw CLI::RuntimeError(code);
}

/// The parameters: the baseline's, or a graph file's (the embedded tabletop graph for "tabletop"),
/// then the flags given.
void resolve_params(SegmentOptions& opt) {
  if (!opt.graph.empty()) {
    auto seg = segmentation_of_graph_arg(opt.graph);
    if (!seg) fail(seg.error(), EXIT_BAD_INPUT);
    opt.params = seg->stages;
    opt.candidates = seg->candidates;
  }
  if (opt.leaf) {
    opt.params.leaf = *opt.leaf;
    opt.params.organized_stride = 0;  // organized frames too: the voxel grid of this leaf
  }
  if (opt.plane_tau) opt.params.ransac.tau = *opt.plane_tau;
  if (opt.plane_iters) opt.params.ransac.max_iterations = *opt.plane_iters;
  if (opt.cluster_tol) opt.params.cluster.tolerance = *opt.cluster_tol;
  if (opt.min_cluster) opt.params.cluster.min_size = *opt.min_cluster;
}

/// The frame with a `label` field (0 none, 1 table, k >= 2 object k - 2: kernels/frame_labels.hpp)
/// in place of any label it had, binary_compressed like the Kinect recordings.
void write_labels(const kernels::SegmentationResult& seg, const SegmentOptions& opt,
                  kernels::PointCloud& cloud) {
  if (!seg.organized) {
    fail("--labels-out needs an organized frame (per-point labels come from the organized chain; " +
             opt.file + " has height 1)",
         EXIT_BAD_INPUT);
  }
  cloud.add_field(kernels::Field::LABEL);
  kernels::frame_labels(cloud.points(), seg.plane.plane, opt.params.ransac.tau, opt.params.roi,
                        seg.labels, seg.candidate_of, cloud.label());
  auto written = formats::write_pcd(cloud, opt.labels_out);
  if (!written) fail(written.error().to_string(), EXIT_FAILURE_GENERIC);
}

void run_segment(SegmentOptions& opt) {
  resolve_params(opt);
  auto cloud_result = formats::read_pcd(opt.file);
  if (!cloud_result) {
    std::cerr << "orthoflow segment: " << cloud_result.error().to_string() << '\n';
    throw CLI::RuntimeError(EXIT_BAD_INPUT);
  }
  nlohmann::json regridded = nullptr;
  if (!opt.graph.empty() && !opt.keep_unorganized && !cloud_result->organized()) {
    if (auto grid = kernels::organize_if_pinhole(*cloud_result)) {
      regridded = {{"width", grid->width}, {"height", grid->height}, {"fx", grid->fx},
                   {"fy", grid->fy},       {"cx", grid->cx},         {"cy", grid->cy}};
    } else {
      regridded = {{"refused", std::string(kernels::to_string(grid.error()))}};
    }
  }
  kernels::SegmentationChain chain(cloud_result->size(), opt.params, opt.candidates);
  std::vector<kernels::SegmentationTimings> runs;
  nlohmann::json out;
  for (int r = 0; r < opt.repeat; ++r) {
    auto seg_result = chain.run(cloud_result->view());
    if (!seg_result) {
      std::cerr << "orthoflow segment: " << seg_result.error().to_string() << '\n';
      throw CLI::RuntimeError(EXIT_FAILURE_GENERIC);
    }
    runs.push_back(seg_result->timings);
    if (r + 1 == opt.repeat) {
      out = to_json(*seg_result, median_timings(runs), plane_input_json(*cloud_result, opt.params));
      out["regridded"] = regridded;
      if (!opt.labels_out.empty()) write_labels(*seg_result, opt, *cloud_result);
    }
  }
  if (opt.json) {
    std::cout << out.dump() << '\n';
  } else {
    print_text(out);
  }
}

}  // namespace

void add_segment_command(CLI::App& app) {
  auto opt = std::make_shared<SegmentOptions>();
  CLI::App* cmd = app.add_subcommand(
      "segment", "Tabletop segmentation of one PCD frame: plane, objects, timings");
  cmd->add_option("FILE", opt->file, "Input .pcd file")->required()->check(CLI::ExistingFile);
  cmd->add_flag("--json", opt->json, "Print one JSON object (plane, inliers, objects, timings_ms)");
  cmd->add_option("--repeat", opt->repeat, "Runs; timings are the median")
      ->check(CLI::Range(1, 100000));
  cmd->add_option(
      "--graph", opt->graph,
      "Take the segmentation parameters from this graph file ('tabletop': the embedded one)");
  cmd->add_flag("--keep-unorganized", opt->keep_unorganized,
                "With --graph: do not put an unorganized cloud back on its pixel grid");
  cmd->add_option("--labels-out", opt->labels_out,
                  "Write the frame as PCD with a label field: 0 no object, 1 table, k >= 2 "
                  "object k - 2 of the objects list (organized frames)");
  cmd->add_option("--leaf", opt->leaf,
                  "Voxel leaf in metres (0: no voxel grid). An organized frame otherwise fits its "
                  "plane on a strided pixel sample; --leaf replaces that sample by this voxel grid")
      ->check(CLI::Range(0.0, 1e6));
  cmd->add_option("--plane-tau", opt->plane_tau, "RANSAC inlier distance, metres")
      ->check(CLI::Range(0.0, 1e6));
  cmd->add_option("--plane-iters", opt->plane_iters, "RANSAC iterations")
      ->check(CLI::Range(1, 100000000));
  cmd->add_option("--cluster-tol", opt->cluster_tol, "Cluster distance tolerance, metres")
      ->check(CLI::Range(1e-6, 1e6));
  cmd->add_option("--min-cluster", opt->min_cluster, "Minimum points per cluster")
      ->check(CLI::Range(1, 100000000));
  cmd->callback([opt] { run_segment(*opt); });
}

}  // namespace orthoflow::apps
