#include "graphs/nodes/segment_params.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "graphs/nodes/node_support.hpp"

namespace orthoflow::graphs {

kernels::SegmentationParams TabletopSegmentation::defaults() noexcept {
  kernels::SegmentationParams p;
  p.cluster = kernels::ClusterParams{0.02F, 50, 200000, 2};
  p.merge_overlap = 0.3F;
  // The work budget (issue 50 item 3), chosen on the 45 mOSD learn frames (docs/SEGMENTATION.md,
  // "The work budget"): their prisms hold 10,000-40,262 pixels, most are clustered at stride 2 and
  // score no worse than at full resolution.
  p.budget = kernels::ObjectBudget{12000, 96};
  return p;
}

Result<void, std::string> parse_preprocess_params(const engine::ParamMap& params,
                                                  kernels::SegmentationParams& p) {
  if (auto ok = params.only({"roi_min_x", "roi_min_y", "roi_min_z", "roi_max_x", "roi_max_y",
                             "roi_max_z", "leaf", "organized_stride"});
      !ok) {
    return err(ok.error());
  }
  std::string e;
  const char* keys[2][3] = {{"roi_min_x", "roi_min_y", "roi_min_z"},
                            {"roi_max_x", "roi_max_y", "roi_max_z"}};
  for (std::size_t axis = 0; axis < 3; ++axis) {
    take(params.number(keys[0][axis], p.roi.min[axis], -100.0, 100.0), p.roi.min[axis], e);
    take(params.number(keys[1][axis], p.roi.max[axis], -100.0, 100.0), p.roi.max[axis], e);
  }
  take(params.number("leaf", p.leaf, 0.0, 1.0), p.leaf, e);
  take(params.integer("organized_stride", p.organized_stride, 0, 64), p.organized_stride, e);
  if (!e.empty()) return err(e);
  return {};
}

namespace {

/// "x,y,z" -> a unit vector; an error for anything else (three finite numbers, not all zero).
Result<std::array<float, 3>, std::string> parse_up(const std::string& text) {
  std::array<float, 3> v{};
  char tail = 0;
  if (std::sscanf(text.c_str(), "%f,%f,%f%c", &v[0], &v[1], &v[2], &tail) != 3)
    return err("table: up must be \"x,y,z\" (the camera's up in the sensor frame), not '" + text +
               "'");
  const float norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!std::isfinite(norm) || norm < 1e-3F)
    return err("table: up '" + text + "' is not a direction");
  for (float& c : v) c /= norm;
  return v;
}

}  // namespace

Result<void, std::string> parse_table_params(const engine::ParamMap& params,
                                             TabletopSegmentation& out) {
  if (auto ok = params.only({"tau", "iterations", "confidence", "seed", "max_tilt_deg",
                             "min_height", "max_height", "min_share", "min_area", "hold_frames",
                             "up", "max_up_age_ms"});
      !ok)
    return err(ok.error());
  kernels::RansacParams& r = out.stages.ransac;
  kernels::TableVerdictParams& v = out.table.verdict;
  std::string e;
  take(params.number("tau", r.tau, 1e-4, 1.0), r.tau, e);
  take(params.integer("iterations", r.max_iterations, 1, 100000), r.max_iterations, e);
  take(params.number("confidence", r.confidence, 0.0, 0.999999), r.confidence, e);
  take(params.integer("seed", static_cast<std::int64_t>(r.seed), 0, INT64_MAX), r.seed, e);
  take(params.number("max_tilt_deg", v.max_tilt_deg, 0.0, 90.0), v.max_tilt_deg, e);
  take(params.number("min_height", v.min_height_m, 0.0, 100.0), v.min_height_m, e);
  take(params.number("max_height", v.max_height_m, 0.0, 100.0), v.max_height_m, e);
  take(params.number("min_share", v.min_share, 0.0, 1.0), v.min_share, e);
  take(params.number("min_area", v.min_area_m2, 0.0, 100.0), v.min_area_m2, e);
  take(params.integer("hold_frames", out.table.hold_frames, 0, 30), out.table.hold_frames, e);
  take(params.integer("max_up_age_ms", out.table.max_up_age_ms, 0, 60000), out.table.max_up_age_ms,
       e);
  std::string up = "none";
  take(params.text("up", "none"), up, e);
  if (!e.empty()) return err(e);
  if (v.min_height_m > v.max_height_m)
    return err(std::string("table: min_height must not exceed max_height"));
  if (up != "none") {
    auto parsed = parse_up(up);
    if (!parsed) return err(parsed.error());
    out.table.up = *parsed;
  }
  return {};
}

Result<void, std::string> parse_objects_params(const engine::ParamMap& params,
                                               TabletopSegmentation& out) {
  if (auto ok = params.only({"h_min",         "h_max",          "tolerance",    "min_points",
                             "max_points",    "pixel_radius",   "min_size",     "max_size",
                             "edge_margin",   "merge_overlap",  "cluster_mode", "crease_angle",
                             "crease_gap",    "normal_offset",  "max_rise",     "depth_change",
                             "stand_height",  "occlusion_rows", "occluder_gap", "occlusion_top",
                             "neck_cell",     "neck_core",      "neck_ratio",   "neck_round",
                             "budget_points", "budget_clusters"});
      !ok) {
    return err(ok.error());
  }
  kernels::SegmentationParams& p = out.stages;
  kernels::CandidateParams& c = out.candidates;
  std::string e;
  take(params.number("h_min", p.h_min, -1.0, 10.0), p.h_min, e);
  take(params.number("h_max", p.h_max, -1.0, 10.0), p.h_max, e);
  take(params.number("tolerance", p.cluster.tolerance, 1e-4, 1.0), p.cluster.tolerance, e);
  take(params.integer("min_points", p.cluster.min_size, 1, UINT32_MAX), p.cluster.min_size, e);
  take(params.integer("max_points", p.cluster.max_size, 1, UINT32_MAX), p.cluster.max_size, e);
  take(params.integer("pixel_radius", p.cluster.pixel_radius, 1, 16), p.cluster.pixel_radius, e);
  take(params.number("merge_overlap", p.merge_overlap, 0.0, 1.0), p.merge_overlap, e);
  const auto mode = params.choice(
      "cluster_mode", p.cluster_mode == kernels::ClusterMode::CROWDED ? "crowded" : "euclidean",
      {"euclidean", "crowded"});
  if (!mode) {
    e += (e.empty() ? "" : "; ") + mode.error();
  } else {
    p.cluster_mode =
        *mode == "crowded" ? kernels::ClusterMode::CROWDED : kernels::ClusterMode::EUCLIDEAN;
  }
  kernels::CreaseParams& k = p.crease;
  take(params.number("crease_angle", k.min_angle_deg, 1.0, 179.0), k.min_angle_deg, e);
  take(params.integer("crease_gap", k.gap, 1, 32), k.gap, e);
  take(params.integer("normal_offset", k.normals.offset, 1, 32), k.normals.offset, e);
  take(params.number("depth_change", k.normals.depth_change, 0.001, 1.0), k.normals.depth_change,
       e);
  take(params.number("max_rise", k.max_rise, 0.0, 1.0), k.max_rise, e);
  take(params.number("stand_height", k.stand_height, 0.0, 1.0), k.stand_height, e);
  take(params.integer("occlusion_rows", k.occlusion_rows, 0, 10000), k.occlusion_rows, e);
  take(params.number("occluder_gap", k.occluder_gap, 0.0, 1.0), k.occluder_gap, e);
  take(params.number("occlusion_top", k.occlusion_top, 0.0, 1.0), k.occlusion_top, e);
  take(params.number("neck_cell", k.neck_cell, 0.0, 0.05), k.neck_cell, e);
  take(params.number("neck_core", k.neck_core, 0.001, 0.3), k.neck_core, e);
  take(params.number("neck_ratio", k.neck_ratio, 0.0, 0.95), k.neck_ratio, e);
  take(params.number("neck_round", k.neck_round, 1.0, 100.0), k.neck_round, e);
  take(params.integer("budget_points", p.budget.max_points, 0, 1U << 24), p.budget.max_points, e);
  take(params.integer("budget_clusters", p.budget.max_refine_clusters, 0, 100000),
       p.budget.max_refine_clusters, e);
  take(params.number("min_size", c.min_size, 0.0, 10.0), c.min_size, e);
  take(params.number("max_size", c.max_size, 0.0, 10.0), c.max_size, e);
  take(params.number("edge_margin", c.edge_margin, -1.0, 1.0), c.edge_margin, e);
  if (!e.empty()) return err(e);
  if (p.h_min >= p.h_max) return err(std::string("objects: h_min must be below h_max"));
  if (p.cluster.min_size > p.cluster.max_size)
    return err(std::string("objects: min_points must not exceed max_points"));
  return {};
}

Result<TabletopSegmentation, std::string> segmentation_of_graph(const engine::GraphSpec& spec) {
  TabletopSegmentation out;
  bool seen[3] = {false, false, false};
  for (const engine::NodeSpec& node : spec.nodes) {
    const int kind = node.kind == "preprocess" ? 0
                     : node.kind == "table"    ? 1
                     : node.kind == "objects"  ? 2
                                               : -1;
    if (kind < 0) continue;
    if (seen[kind])
      return err("graph '" + spec.name + "': more than one " + node.kind + " node ('" + node.name +
                 "')");
    seen[kind] = true;
    Result<void, std::string> ok = kind == 0   ? parse_preprocess_params(node.params, out.stages)
                                   : kind == 1 ? parse_table_params(node.params, out)
                                               : parse_objects_params(node.params, out);
    if (!ok) return err("node '" + node.name + "': " + ok.error());
  }
  return out;
}

}  // namespace orthoflow::graphs
