#pragma once
/// @file
/// @brief Pieces both learners share: best/runner-up ranking of category scores and validation of
/// restored categories. Internal to learning/.
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "learning/learner.hpp"

namespace orthoflow::learning {

/// @brief Keeps the best and second-best score offered, in offer order; ties keep the earlier offer
/// (categories are offered by increasing id), NaN scores are never ranked. No allocation.
class RankedScores {
 public:
  /// @param higher_is_better true for log-likelihoods, false for distances.
  explicit RankedScores(bool higher_is_better) noexcept : higher_(higher_is_better) {}

  void offer(float score, CategoryId id, const Label& label) noexcept {
    if (std::isnan(score)) { return; }
    if (best_ == NO_CATEGORY || better(score, best_score_)) {
      second_ = best_, second_score_ = best_score_, second_label_ = best_label_;
      best_ = id, best_score_ = score, best_label_ = label;
    } else if (second_ == NO_CATEGORY || better(score, second_score_)) {
      second_ = id, second_score_ = score, second_label_ = label;
    }
  }
  /// @brief The ranking as a Prediction (unknown only when nothing was ranked; callers apply CT).
  [[nodiscard]] Prediction prediction(std::uint64_t generation) const noexcept {
    Prediction p;
    p.generation = generation;
    p.unknown = best_ == NO_CATEGORY;
    p.category = best_;
    p.label = best_label_;
    p.score = best_ == NO_CATEGORY ? std::numeric_limits<float>::quiet_NaN() : best_score_;
    p.runner_up = second_label_;
    p.runner_up_score =
        second_ == NO_CATEGORY ? std::numeric_limits<float>::quiet_NaN() : second_score_;
    return p;
  }
  /// @brief The answer to a descriptor of the wrong length: unknown, score NaN.
  [[nodiscard]] static Prediction wrong_length(std::uint64_t generation) noexcept {
    return RankedScores(false).prediction(generation);
  }

 private:
  [[nodiscard]] bool better(float a, float b) const noexcept { return higher_ ? a > b : a < b; }
  bool higher_;
  CategoryId best_ = NO_CATEGORY;
  CategoryId second_ = NO_CATEGORY;
  float best_score_ = 0.0F;
  float second_score_ = 0.0F;
  Label best_label_;
  Label second_label_;
};

/// @brief One category's views and the sum of their pairwise distances, as the ICD needs them.
struct PairSum {
  std::size_t views = 0;
  double sum = 0.0;  ///< over unordered pairs of distinct views
};

/// @brief ICD of every category (thesis chapter 5): the mean pairwise distance of a category of two
/// or more views (never below @p min_icd); a category of one view takes the mean of those, or
/// @p default_icd while none has two. Writes one ICD per category to @p icd. @return their mean
/// (approach II), or @p default_icd when there is no category.
float category_icds(std::span<const PairSum> categories, float min_icd, float default_icd,
                    std::vector<float>& icd);

/// @brief The instance-style decision value of an OCD (thesis chapter 5): the OCD itself when not
/// @p normalise (plain nearest), approach I OCD / ICD, approach II (@p mean_approach)
/// 2 OCD / (ICD + mean ICD).
[[nodiscard]] inline float nocd_score(float ocd, float icd, float mean_icd, bool normalise,
                                      bool mean_approach) noexcept {
  if (!normalise) return ocd;
  return mean_approach ? 2.0F * ocd / (icd + mean_icd) : ocd / icd;
}

/// @brief The instance-style Unknown rule: nothing ranked, or the best score above @p ct (or NaN).
[[nodiscard]] inline Prediction with_threshold(Prediction p, float ct) noexcept {
  p.unknown = p.category == NO_CATEGORY || !(p.score <= ct);
  if (p.unknown) p.category = NO_CATEGORY;
  return p;
}

/// @brief OF_ENFORCEs what every ICD-using learner requires: finite default_icd and min_icd > 0,
/// and a CT that is not NaN. @p who names the configuration in the message.
void enforce_icd_config(float default_icd, float min_icd, float ct, const char* who);

/// @brief Checks restored categories: labels, views (when @p need_views or present), and that no id
/// or label appears twice (DUPLICATE_ID).
[[nodiscard]] Result<void, LearnError> validate_restored(
    std::span<const RestoredCategory> categories, std::size_t length, bool histograms) noexcept;

}  // namespace orthoflow::learning
