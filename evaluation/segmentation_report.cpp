// The segmentation reports (evaluation/segmentation_eval.hpp): every segmenter's rows and totals as
// one JSON document, and as GitHub Markdown (summary, per category, per frame). Running and
// scoring the segmenters is in segmentation_eval.cpp.
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "evaluation/segmentation_eval.hpp"

namespace orthoflow::evaluation {

namespace {

nlohmann::json counts_json(const SegmentationCounts& c) {
  return {{"truth", c.truth},
          {"predicted", c.predicted},
          {"matched", c.matched},
          {"over", c.over},
          {"under", c.under},
          {"precision", c.precision()},
          {"recall", c.recall()},
          {"mean_matched_iou", c.matched == 0 ? 0.0 : c.matched_iou / double(c.matched)}};
}

nlohmann::json totals_json(const SegTotals& t) {
  const std::size_t scored = t.frames - t.failed;
  return {{"frames", t.frames},
          {"failed", t.failed},
          {"objects", counts_json(t.objects)},
          {"plane_correct", t.plane_correct},
          {"plane_fallbacks", t.plane_fallbacks},
          {"mean_plane_share", scored == 0 ? 0.0 : t.plane_share_sum / double(scored)},
          {"worst_plane_share", scored == 0 ? 0.0 : t.worst_plane_share},
          {"mean_ms", scored == 0 ? 0.0 : t.ms_sum / double(scored)}};
}

std::string fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

std::string totals_cells(const SegTotals& t) {
  const std::size_t scored = t.frames - t.failed;
  const auto& o = t.objects;
  return std::to_string(t.frames) + " | " + std::to_string(t.failed) + " | " +
         std::to_string(t.plane_correct) + "/" + std::to_string(scored) + " | " +
         fixed(scored == 0 ? 0.0 : t.worst_plane_share, 3) + " | " + std::to_string(o.truth) +
         " | " + std::to_string(o.predicted) + " | " + std::to_string(o.matched) + " | " +
         fixed(o.precision(), 3) + " | " + fixed(o.recall(), 3) + " | " + std::to_string(o.over) +
         " | " + std::to_string(o.under) + " | " +
         fixed(scored == 0 ? 0.0 : t.ms_sum / double(scored), 2);
}

constexpr const char* TOTALS_HEADER =
    "frames | failed | plane correct | worst plane share | objects | predicted | matched | "
    "precision | recall | over | under | mean ms |\n";
constexpr const char* TOTALS_RULE = "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";

}  // namespace

std::string segmentation_json(const std::vector<SegReport>& reports) {
  nlohmann::json out = nlohmann::json::array();
  for (const SegReport& r : reports) {
    nlohmann::json frames = nlohmann::json::array();
    for (const SegFrameRow& f : r.frames) {
      nlohmann::json row = {{"frame", f.name}, {"category", f.category}};
      if (!f.error.empty()) {
        row["error"] = f.error;
      } else {
        const PlaneQuality& p = f.score.plane;
        row["objects"] = counts_json(f.score.objects);
        row["plane"] = {
            {"table_points", p.table_points}, {"near", p.near},   {"share", p.share()},
            {"correct", p.correct()},         {"rms_m", p.rms_m}, {"angle_deg", p.angle_deg},
            {"fallback", f.plane_fallback}};
        row["ms"] = f.ms;
      }
      frames.push_back(std::move(row));
    }
    nlohmann::json categories = nlohmann::json::object();
    for (const auto& [name, t] : r.by_category) categories[name] = totals_json(t);
    out.push_back({{"segmenter", r.segmenter},
                   {"dataset", r.dataset},
                   {"total", totals_json(r.total)},
                   {"categories", categories},
                   {"frames", frames}});
  }
  return out.dump(2) + "\n";
}

std::string segmentation_markdown(const std::vector<SegReport>& reports) {
  std::string md = "# Segmentation on labelled frames\n\n";
  if (!reports.empty()) md += "Dataset: `" + reports.front().dataset + "`. ";
  md +=
      "An object is found when one prediction covers it at pixel IoU >= 0.5 (one-to-one); the "
      "plane is correct when >= 90 % of the labelled table points lie within 1 cm of it.\n\n";
  md += std::string("| segmenter | ") + TOTALS_HEADER + TOTALS_RULE;
  for (const SegReport& r : reports)
    md += "| " + r.segmenter + " | " + totals_cells(r.total) + " |\n";
  bool any_category = false;
  for (const SegReport& r : reports) any_category = any_category || !r.by_category.empty();
  if (any_category) {
    md += std::string("\n## Per category\n\n| category | segmenter | ") + TOTALS_HEADER + "|---" +
          TOTALS_RULE;
    std::map<std::string, std::vector<std::pair<std::string, const SegTotals*>>> rows;
    for (const SegReport& r : reports) {
      for (const auto& [name, t] : r.by_category) rows[name].emplace_back(r.segmenter, &t);
    }
    for (const auto& [name, list] : rows) {
      for (const auto& [who, t] : list)
        md += "| " + name + " | " + who + " | " + totals_cells(*t) + " |\n";
    }
  }
  md +=
      "\n## Per frame\n\n| frame | category | segmenter | plane share | angle deg | objects | "
      "predicted | matched | over | under | ms |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; !reports.empty() && i < reports.front().frames.size(); ++i) {
    for (const SegReport& r : reports) {
      if (i >= r.frames.size()) continue;
      const SegFrameRow& f = r.frames[i];
      md += "| " + f.name + " | " + f.category + " | " + r.segmenter + " | ";
      if (!f.error.empty()) {
        md += "failed: " + f.error + " |||||||\n";
        continue;
      }
      const auto& o = f.score.objects;
      md += fixed(f.score.plane.share(), 3) + (f.plane_fallback ? " (fallback)" : "") + " | " +
            fixed(f.score.plane.angle_deg, 2) + " | " + std::to_string(o.truth) + " | " +
            std::to_string(o.predicted) + " | " + std::to_string(o.matched) + " | " +
            std::to_string(o.over) + " | " + std::to_string(o.under) + " | " + fixed(f.ms, 2) +
            " |\n";
    }
  }
  return md;
}

}  // namespace orthoflow::evaluation
