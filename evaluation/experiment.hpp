#pragma once
/// @file
/// @brief One evaluation command: a protocol run for every variant and every repetition, in
/// parallel over (variant, run) pairs with oneTBB. Every random choice (folds, category orders,
/// view orders, context sizes, noise) depends only on the seed, the run and the dataset, never on
/// the variant or the thread count, so the results are identical whatever the parallelism and
/// comparable across variants.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "evaluation/cross_validation.hpp"
#include "evaluation/simulated_teacher.hpp"

namespace orthoflow::evaluation {

class Progress;

enum class Protocol : std::uint8_t { CV10, TEACHER, TEACHER_CONTEXT, NOISE, DOWNSAMPLE };
[[nodiscard]] const char* to_string(Protocol p) noexcept;

struct EvalOptions {
  Protocol protocol = Protocol::CV10;
  std::vector<Variant> variants{Variant{}};
  std::size_t runs = 10;
  std::uint64_t seed = 1;
  std::size_t folds = 10;
  /// Noise sigmas / voxel leaves in metres; empty = thesis 6.4.3 (1..10 mm by 1; 1, 2, 4, ..., 20
  /// mm).
  std::vector<double> levels_m;
  std::size_t threads = 0;          ///< 0 = oneTBB's default
  std::filesystem::path cache_dir;  ///< empty = no descriptor cache
  TeacherConfig teacher{};
};

/// @brief The levels @p options asks for (its own, or the protocol's defaults).
[[nodiscard]] std::vector<double> protocol_levels(const EvalOptions& options);

struct LevelResult {
  double amount_m = 0.0;         ///< 0 = the clean test views
  std::vector<double> accuracy;  ///< per run
};

struct VariantResult {
  Variant variant;
  std::vector<CvResult> cv;  ///< cv10: per run
  std::vector<TeacherRun>
      teacher;  ///< teacher and teacher-context (the runs that give ALC): per run
  std::vector<TeacherRun> context;  ///< teacher-context: per run
  std::vector<std::size_t> rho;     ///< teacher-context: size of context A per run
  double alc = 0.0;  ///< teacher-context: mean NLC of the runs without context change
  std::vector<LevelResult> levels;  ///< noise / downsample
};

struct Evaluation {
  EvalOptions options;
  std::vector<std::string> categories;
  std::size_t views = 0;
  std::size_t instances = 0;
  std::vector<VariantResult> variants;
  DescribeStats describe;  ///< summed over every descriptor table
  std::vector<std::string> warnings;
  double seconds = 0.0;  ///< wall time of evaluate()
};

/// @brief Work units evaluate() reports to a Progress (descriptors computed or loaded + protocol
/// runs).
[[nodiscard]] std::size_t evaluation_work(const Dataset& dataset, const EvalOptions& options);

/// @brief Runs @p options.protocol on @p dataset. Errors: BAD_CONFIG (no variant, runs 0, folds <
/// 2, negative levels), TOO_FEW_VIEWS, TOO_FEW_CATEGORIES (teacher: 2, teacher-context: 3),
/// BAD_VIEW / BAD_DATASET from describing the views.
[[nodiscard]] Result<Evaluation, EvalError> evaluate(const Dataset& dataset,
                                                     const EvalOptions& options,
                                                     Progress* progress);

}  // namespace orthoflow::evaluation
