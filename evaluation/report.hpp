#pragma once
/// @file
/// @brief What an evaluation writes: `results.json` (every run's numbers), `summary.md` (one table,
/// mean
/// +- sample standard deviation over runs) and the plots (PNG and SVG): learned categories vs
/// question / correction iterations and global accuracy vs learned categories (teacher protocols),
/// accuracy vs noise or voxel size (robustness protocols).
#include <filesystem>
#include <string>
#include <vector>

#include "evaluation/experiment.hpp"
#include "evaluation/line_plot.hpp"

namespace orthoflow::evaluation {

/// @brief The whole evaluation as pretty-printed JSON (schema in docs/EVALUATION.md).
[[nodiscard]] std::string results_json(const Evaluation& evaluation);
/// @brief The summary table (GitHub Markdown) with a heading naming the protocol, dataset size and
/// seed.
[[nodiscard]] std::string summary_markdown(const Evaluation& evaluation);
/// @brief The plots of @p evaluation, each with its file stem ("learned_categories", ...).
[[nodiscard]] std::vector<std::pair<std::string, PlotSpec>> evaluation_plots(
    const Evaluation& evaluation);
/// @brief Writes results.json, summary.md and every plot as <stem>.png and <stem>.svg into @p
/// out_dir (created if missing). @return the files written; WRITE_FAILED naming the file otherwise.
[[nodiscard]] Result<std::vector<std::filesystem::path>, EvalError> write_report(
    const Evaluation& evaluation, const std::filesystem::path& out_dir);

}  // namespace orthoflow::evaluation
