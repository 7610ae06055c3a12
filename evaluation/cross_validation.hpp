#pragma once
/// @file
/// @brief k-fold cross-validation (thesis section 6.4: 10-fold): stratified seeded folds, a fresh
/// learner per fold taught every training view of each class, every held-out view asked once. The
/// test views may be perturbed copies (noise, downsampling: robustness protocols) of the same
/// files.
#include <cstdint>
#include <vector>

#include "evaluation/dataset.hpp"
#include "evaluation/descriptors.hpp"
#include "evaluation/metrics.hpp"
#include "evaluation/variant.hpp"

namespace orthoflow::evaluation {

/// @brief Fold of every dataset view.
struct Folds {
  std::size_t count = 0;
  std::vector<std::uint32_t> fold_of_view;
};

/// @brief Stratified folds: each category's views are shuffled by a generator seeded with (@p seed,
/// category) and dealt round-robin, starting at a seeded fold, so every fold holds about 1/k of
/// every category. Errors: BAD_CONFIG for k < 2; TOO_FEW_VIEWS when a category has fewer than 2
/// views (it could never be both taught and tested).
[[nodiscard]] Result<Folds, EvalError> make_folds(const Dataset& dataset, std::size_t k,
                                                  std::uint64_t seed);

/// @brief Result of one cross-validation.
struct CvResult {
  Confusion confusion;
  Scores scores;
  std::vector<double> fold_accuracy;
};

/// @brief Runs the cross-validation of @p variant: fold f is taught from @p train rows of the other
/// folds and asked the @p test rows of fold f. @pre train and test have one row per dataset view.
/// @note Deterministic; single-threaded (callers parallelise over runs).
[[nodiscard]] CvResult cross_validate(const Dataset& dataset, const Folds& folds,
                                      const DescriptorTable& train, const DescriptorTable& test,
                                      const Variant& variant);

}  // namespace orthoflow::evaluation
