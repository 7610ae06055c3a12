// Segmentation on labelled frames (evaluation/segmentation_eval.hpp): the product's chain as a
// segmenter, the dataset's frames and names, every frame segmented and scored, and the label
// pictures. The JSON and Markdown reports are in segmentation_report.cpp.
#include "evaluation/segmentation_eval.hpp"

#include <cairo.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "formats/pcd_io.hpp"
#include "kernels/frame_labels.hpp"
#include "kernels/segmentation_chain.hpp"

namespace orthoflow::evaluation {

namespace fs = std::filesystem;

Segmenter make_chain_segmenter(const kernels::SegmentationParams& params,
                               const kernels::CandidateParams& candidates,
                               const kernels::TableVerdictParams* verdict) {
  auto chain = std::make_shared<std::optional<kernels::SegmentationChain>>();
  auto capacity = std::make_shared<std::size_t>(0);
  const std::optional<kernels::TableVerdictParams> judge =
      verdict ? std::optional(*verdict) : std::nullopt;
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
    if (judge) {
      const auto& up = cloud.info.up;
      const bool has_up = up[0] != 0.0F || up[1] != 0.0F || up[2] != 0.0F;
      const kernels::TableJudgement j =
          kernels::judge_table(seg->plane.plane, seg->plane.inliers, seg->plane_sample, seg->hull_u,
                               seg->hull_v, has_up ? &up : nullptr, *judge);
      if (j.reason != kernels::TableReason::ACCEPTED) {
        char why[160];
        std::snprintf(why, sizeof why,
                      "table refused: %s (share %.3f, area %.3f m2, height %.3f m)",
                      std::string(kernels::table_reason_name(j.reason)).c_str(), double(j.share),
                      double(j.area_m2), double(j.height_m));
        out.error = why;
        return out;
      }
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
