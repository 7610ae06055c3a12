#include "evaluation/segmentation_eval.hpp"

#include <cairo.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "formats/pcd_io.hpp"
#include "kernels/frame_labels.hpp"
#include "kernels/segmentation_chain.hpp"

namespace orthoflow::evaluation {

namespace fs = std::filesystem;

Segmenter make_chain_segmenter(const kernels::SegmentationParams& params,
                               const kernels::CandidateParams& candidates) {
  auto chain = std::make_shared<std::optional<kernels::SegmentationChain>>();
  auto capacity = std::make_shared<std::size_t>(0);
  return [=](const kernels::PointCloud& cloud) {
    SegmenterOutput out;
    if (!chain->has_value() || cloud.size() > *capacity) {
      *capacity = cloud.size();
      chain->emplace(cloud.size(), params, candidates);
    }
    auto seg = (*chain)->run(cloud.view());
    if (!seg) {
      out.error = seg.error().to_string();
      return out;
    }
    if (!seg->organized) {
      out.error = "per-point labels need the organized chain (an organized frame, use_organized)";
      return out;
    }
    out.labels.resize(cloud.size());
    kernels::frame_labels(cloud.points(), seg->plane.plane, params.ransac.tau, params.roi,
                          seg->labels, seg->candidate_of, out.labels);
    out.plane = seg->plane.plane;
    out.plane_fallback = seg->plane_check.switched;
    out.ms = seg->timings.total;
    return out;
  };
}

void SegTotals::add(const SegFrameRow& row) {
  ++frames;
  if (!row.error.empty()) {
    ++failed;
    return;
  }
  objects += row.score.objects;
  plane_correct += row.score.plane.correct() ? 1U : 0U;
  plane_fallbacks += row.plane_fallback ? 1U : 0U;
  plane_share_sum += row.score.plane.share();
  worst_plane_share = std::min(worst_plane_share, row.score.plane.share());
  ms_sum += row.ms;
}

namespace {

/// Natural order: digit runs compare as numbers.
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) &&
        std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      const std::string na = a.substr(i, ie - i), nb = b.substr(j, je - j);
      const std::size_t za = na.find_first_not_of('0'), zb = nb.find_first_not_of('0');
      const std::string ta = za == std::string::npos ? "" : na.substr(za);
      const std::string tb = zb == std::string::npos ? "" : nb.substr(zb);
      if (ta.size() != tb.size()) return ta.size() < tb.size();
      if (ta != tb) return ta < tb;
      i = ie, j = je;
      continue;
    }
    if (a[i] != b[j]) return a[i] < b[j];
    ++i, ++j;
  }
  return a.size() - i < b.size() - j;
}

EvalError error(EvalError::Code code, std::string message) { return {code, std::move(message)}; }

}  // namespace

Result<std::vector<fs::path>, EvalError> labelled_frames(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    return err(error(EvalError::Code::BAD_DATASET, dir.string() + " is not a directory"));
  }
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.is_regular_file() && entry.path().extension() == ".pcd") out.push_back(entry.path());
  }
  if (ec) return err(error(EvalError::Code::BAD_DATASET, dir.string() + ": " + ec.message()));
  if (out.empty()) return err(error(EvalError::Code::BAD_DATASET, dir.string() + " has no .pcd"));
  std::sort(out.begin(), out.end(), [](const fs::path& a, const fs::path& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return out;
}

Result<std::map<std::string, std::string>, EvalError> read_frame_names(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return err(error(EvalError::Code::BAD_CONFIG, "cannot read " + file.string()));
  std::map<std::string, std::string> names;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string stem, category, extra;
    if (!(words >> stem)) continue;
    if (!(words >> category) || (words >> extra)) {
      return err(
          error(EvalError::Code::BAD_CONFIG, file.string() + ":" + std::to_string(number) +
                                                 ": expected 'frame-stem category' (two words)"));
    }
    names[stem] = category;
  }
  return names;
}

Result<SegReport, EvalError> evaluate_segmentation(const std::vector<fs::path>& frames,
                                                   const std::string& segmenter_name,
                                                   const Segmenter& segmenter,
                                                   const SegEvalOptions& options) {
  SegReport report;
  report.segmenter = segmenter_name;
  report.dataset = frames.empty() ? std::string() : frames.front().parent_path().string();
  if (!options.png_dir.empty()) {
    std::error_code ec;
    fs::create_directories(options.png_dir, ec);
    if (ec) {
      return err(error(EvalError::Code::WRITE_FAILED,
                       "cannot create " + options.png_dir.string() + ": " + ec.message()));
    }
  }
  for (const fs::path& path : frames) {
    SegFrameRow row;
    row.name = path.stem().string();
    if (const auto it = options.names.find(row.name); it != options.names.end()) {
      row.category = it->second;
    }
    auto cloud = formats::read_pcd(path);
    if (!cloud) {
      row.error = cloud.error().to_string();
    } else if (!cloud->has(kernels::Field::LABEL)) {
      row.error = path.string() + " has no label field (ground truth)";
    } else if (!cloud->organized()) {
      row.error = path.string() + " is not organized (per-pixel ground truth needs the grid)";
    } else {
      SegmenterOutput out = segmenter(*cloud);
      if (!out.error.empty()) {
        row.error = out.error;
      } else if (out.labels.size() != cloud->size()) {
        row.error = "the segmenter labelled " + std::to_string(out.labels.size()) + " of " +
                    std::to_string(cloud->size()) + " points";
      } else {
        row.score.objects = score_objects(cloud->label(), out.labels);
        row.score.plane = score_plane(cloud->points(), cloud->label(), out.plane);
        row.ms = out.ms;
        row.plane_fallback = out.plane_fallback;
        if (!options.png_dir.empty()) {
          auto png = write_label_png(options.png_dir / (row.name + ".png"), cloud->width(),
                                     cloud->height(), cloud->label(), out.labels);
          if (!png) return err(png.error());
        }
      }
    }
    report.total.add(row);
    if (!row.category.empty()) report.by_category[row.category].add(row);
    report.frames.push_back(std::move(row));
    if (options.progress != nullptr) options.progress->advance();
  }
  return report;
}

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

namespace {

/// A colour per label: invalid black, table grey, objects from a fixed palette by label.
std::uint32_t colour_of(std::uint32_t label, bool truth) {
  static constexpr std::uint32_t PALETTE[] = {0xe6194b, 0x3cb44b, 0xffe119, 0x4363d8, 0xf58231,
                                              0x911eb4, 0x46f0f0, 0xf032e6, 0xbcf60c, 0xfabebe,
                                              0x008080, 0xe6beff, 0x9a6324, 0xfffac8, 0x800000,
                                              0xaaffc3, 0x808000, 0xffd8b1, 0x000075};
  constexpr std::size_t N = sizeof PALETTE / sizeof PALETTE[0];
  if (truth) {
    if (truth_table(label)) return 0x707070;
    const std::uint32_t object = truth_object(label);
    return object == 0 ? 0x000000 : PALETTE[(object - 2) % N];
  }
  if (label == 0) return 0x000000;
  if (label == 1) return 0x707070;
  return PALETTE[(label - 2) % N];
}

}  // namespace

Result<void, EvalError> write_label_png(const fs::path& path, std::uint32_t width,
                                        std::uint32_t height, std::span<const std::uint32_t> truth,
                                        std::span<const std::uint32_t> predicted) {
  const int w = static_cast<int>(width), h = static_cast<int>(height);
  const std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, 2 * w, h), cairo_surface_destroy);
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
    return err(error(EvalError::Code::WRITE_FAILED, "cannot draw " + path.string()));
  }
  cairo_surface_flush(surface.get());
  unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  for (int y = 0; y < h; ++y) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x);
      row[x] = colour_of(truth[i], true);
      row[w + x] = colour_of(predicted[i], false);
    }
  }
  cairo_surface_mark_dirty(surface.get());
  if (cairo_surface_write_to_png(surface.get(), path.c_str()) != CAIRO_STATUS_SUCCESS) {
    return err(error(EvalError::Code::WRITE_FAILED, "cannot write " + path.string()));
  }
  return {};
}

}  // namespace orthoflow::evaluation
