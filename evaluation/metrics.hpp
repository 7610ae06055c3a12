#pragma once
/// @file
/// @brief Classical classification measures (thesis section 6.1.2): a confusion matrix with an
/// "unknown" column, accuracy, and micro / macro precision and recall.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace orthoflow::evaluation {

/// @brief counts[t * (classes + 1) + p]: views of true class t predicted as p; column `classes` =
/// unknown.
struct Confusion {
  std::size_t classes = 0;
  std::vector<std::size_t> counts;
  explicit Confusion(std::size_t n = 0) : classes(n), counts(n * (n + 1), 0) {}
  /// @brief Records one answer; @p predicted empty = unknown. @pre truth < classes, *predicted <
  /// classes
  void add(std::uint32_t truth, std::optional<std::uint32_t> predicted);
  /// @brief Adds every count of @p other (same class count).
  void merge(const Confusion& other);
  [[nodiscard]] std::size_t at(std::size_t truth, std::size_t predicted) const {
    return counts[truth * (classes + 1) + predicted];
  }
  [[nodiscard]] std::size_t total() const;
};

/// @brief Summary measures of a confusion matrix.
/// micro precision = correct / answers naming a class; micro recall = accuracy = correct / all
/// answers. Macro measures average the per-class values over every class; a class never predicted
/// has precision 0, a class never asked is left out of the recall average.
struct Scores {
  double accuracy = 0.0;
  double micro_precision = 0.0;
  double micro_recall = 0.0;
  double macro_precision = 0.0;
  double macro_recall = 0.0;
  std::size_t answers = 0;
  std::size_t unknown = 0;
};

[[nodiscard]] Scores score(const Confusion& confusion);

/// @brief Mean and sample standard deviation (0 for fewer than two values).
struct MeanStd {
  double mean = 0.0;
  double std = 0.0;
};
[[nodiscard]] MeanStd mean_std(const std::vector<double>& values);

}  // namespace orthoflow::evaluation
