#pragma once
/// @file
/// @brief A dataset of segmented object views laid out as `DIR/<category>/<instance>/<view>.pcd`
/// (the layout `orthoflow synth-dataset` writes; real views can be arranged the same way), scanned
/// into sorted lists so that every index below is the same on every machine for the same tree.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "evaluation/eval_error.hpp"

namespace orthoflow::evaluation {

/// @brief One view file.
struct DatasetView {
  std::uint32_t category = 0;  ///< index into Dataset::categories
  std::uint32_t instance = 0;  ///< index into Dataset::instances
  std::string relative;        ///< "<category>/<instance>/<view>.pcd" with '/' separators
};

/// @brief The scanned tree. Categories, instances and views are sorted by name (byte order).
struct Dataset {
  std::filesystem::path root;
  std::vector<std::string> categories;
  std::vector<std::string> instances;  ///< "<category>/<instance>"
  std::vector<DatasetView> views;      ///< grouped by category, then instance, then file name
  /// @brief Indices into views of every view of @p category, in views order.
  [[nodiscard]] std::vector<std::size_t> views_of(std::uint32_t category) const;
};

/// @brief Scans @p root. Directories and files whose name starts with '.' are skipped (e.g.
/// caches); other files than .pcd are ignored where the layout allows files (top level, instance
/// folders). Errors (BAD_DATASET): @p root missing or not a directory; a .pcd file at the wrong
/// depth; a category name longer than learning::LABEL_MAX_BYTES; a category with no view; no view
/// at all.
[[nodiscard]] Result<Dataset, EvalError> scan_dataset(const std::filesystem::path& root);

}  // namespace orthoflow::evaluation
