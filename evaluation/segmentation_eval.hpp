#pragma once
/// @file
/// @brief `orthoflow evaluate-segmentation --dataset DIR`: a segmenter over every labelled frame of
/// a directory (mOSD layout: DIR/*.pcd, organized, with a label field), scored frame by frame
/// (evaluation/segmentation_score.hpp), summed over the dataset and per scene category, written as
/// JSON and Markdown, with a label picture per frame on request. The segmenter is a function, so
/// the product's chain (make_chain_segmenter) and a reference (PCL's chain in bench/vs_pcl) are
/// scored by the same code on the same frames.
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "evaluation/eval_error.hpp"
#include "evaluation/progress.hpp"
#include "evaluation/segmentation_score.hpp"
#include "kernels/object_candidates.hpp"
#include "kernels/point_cloud.hpp"
#include "kernels/table_verdict.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::evaluation {

/// @brief What a segmenter says about one frame: per-point labels (frame_labels() convention), its
/// plane, and whether and why it failed.
struct SegmenterOutput {
  std::vector<std::uint32_t> labels;  ///< one per point; empty when failed
  kernels::Plane plane{};
  double ms = 0.0;              ///< the segmenter's own time for the frame
  bool plane_fallback = false;  ///< the segmenter's first plane was not the table (it switched)
  std::string error;            ///< non-empty: the segmenter failed on this frame
};

using Segmenter = std::function<SegmenterOutput(const kernels::PointCloud&)>;

/// @brief The product's chain (kernels::SegmentationChain) with these parameters, as a segmenter.
/// Frames larger than any before resize the chain (off the frame path: this is offline scoring).
/// @param verdict the table node's verdict (kernels/table_verdict.hpp), or null for none: a frame
/// whose plane it refuses is a failed frame ("table refused: REASON ..."), as the product would
/// report no table and no objects. "Up" is the frame's own (FrameInfo::up) when it carries one.
[[nodiscard]] Segmenter make_chain_segmenter(const kernels::SegmentationParams& params,
                                             const kernels::CandidateParams& candidates,
                                             const kernels::TableVerdictParams* verdict = nullptr);

struct SegFrameRow {
  std::string name;      ///< file stem
  std::string category;  ///< from the names file, or empty
  std::string error;     ///< non-empty: unreadable frame or a failed segmenter (not scored)
  FrameScore score;
  double ms = 0.0;
  bool plane_fallback = false;
};

struct SegTotals {
  std::size_t frames = 0, failed = 0, plane_correct = 0, plane_fallbacks = 0;
  SegmentationCounts objects;
  double plane_share_sum = 0.0;  ///< sum over scored frames of PlaneQuality::share()
  double worst_plane_share = 1.0;
  double ms_sum = 0.0;
  void add(const SegFrameRow& row);
};

struct SegReport {
  std::string segmenter;  ///< "orthoflow", "pcl", ...
  std::string dataset;
  std::vector<SegFrameRow> frames;
  SegTotals total;
  std::map<std::string, SegTotals> by_category;
};

/// @brief The *.pcd files of @p dir in natural order (learn2 before learn10). BAD_DATASET when
/// the directory is missing or has none.
[[nodiscard]] Result<std::vector<std::filesystem::path>, EvalError> labelled_frames(
    const std::filesystem::path& dir);

/// @brief "stem category" per line ('#' comments, blank lines ignored). BAD_CONFIG names the line.
[[nodiscard]] Result<std::map<std::string, std::string>, EvalError> read_frame_names(
    const std::filesystem::path& file);

struct SegEvalOptions {
  std::map<std::string, std::string> names;  ///< stem -> category
  std::filesystem::path png_dir;             ///< non-empty: one <stem>.png per frame
  Progress* progress = nullptr;
};

/// @brief Runs @p segmenter on every frame and scores it. An unreadable frame, one without a label
/// field or one the segmenter fails on is a row with an error, counted as failed, never scored.
/// WRITE_FAILED when a picture cannot be written.
[[nodiscard]] Result<SegReport, EvalError> evaluate_segmentation(
    const std::vector<std::filesystem::path>& frames, const std::string& segmenter_name,
    const Segmenter& segmenter, const SegEvalOptions& options);

/// @brief All reports as one JSON document (schema in docs/SEGMENTATION.md).
[[nodiscard]] std::string segmentation_json(const std::vector<SegReport>& reports);
/// @brief Summary (one row per segmenter), per-category and per-frame tables, GitHub Markdown.
[[nodiscard]] std::string segmentation_markdown(const std::vector<SegReport>& reports);

/// @brief Writes a picture of @p truth (left) and @p predicted (right) labels, width x height
/// pixels each: invalid black, table grey, each object its own colour.
[[nodiscard]] Result<void, EvalError> write_label_png(const std::filesystem::path& path,
                                                      std::uint32_t width, std::uint32_t height,
                                                      std::span<const std::uint32_t> truth,
                                                      std::span<const std::uint32_t> predicted);

}  // namespace orthoflow::evaluation
