#pragma once
/// @file
/// @brief Naive Bayes open-ended learner (thesis chapter 5, model-based learning; PIPELINE.md
/// section 7). A category is (N_k, a_k): the number of views taught and the per-bin accumulator.
/// - Descriptors are normalised histograms (each GOOD projection sums to 1). They are turned into
/// counts
///   by a fixed scale: x'_i = count_scale * descriptor_i (count_scale = pseudo-points per
///   projection). The same scale forms y_i from a query, so a view counts as count_scale points per
///   projection.
/// - a_ki = sum over taught views of x'_i;  P(C_k) = N_k / N;  P(x_i | C_k) = (a_ki + 1) / sum_j
/// (a_kj + 1)
///   (Laplace smoothing, thesis eq. "update_p").
/// - score = log P(C_k) + sum_i y_i log P(x_i | C_k); label = argmax score. Memory per category is
///   constant (one row of descriptor_length floats). Unknown is reported only when nothing is
///   learned.
#include "learning/learner_skeleton.hpp"

namespace orthoflow::learning {

/// @brief Plain configuration of BayesLearner (validated by the constructor: OF_ENFORCE).
struct BayesConfig {
  std::size_t descriptor_length = 675;  ///< 3 n^2 (n = 15)
  float count_scale = 100.0F;  ///< pseudo-points per projection: y_i = count_scale * descriptor_i
};

/// @brief Adds every view of @p views (unscaled) into @p sums (sum of descriptors, the stored form
/// of a_k / scale).
/// @pre sums.size() == views.length. @note No allocation; deterministic.
void accumulate_views(DescriptorBatch views, std::span<double> sums) noexcept;
/// @brief Takes every view of @p views back out of @p sums (the inverse of accumulate_views; a bin
/// never goes below 0). @pre sums.size() == views.length.
void subtract_views(DescriptorBatch views, std::span<double> sums) noexcept;

/// @brief Naive Bayes learner, see file comment. Thread-safe as described in learning/learner.hpp.
/// @note ask() computes each category's dot product y . log P(x | C_k) with Eigen (vectorised); it
/// is deterministic for one snapshot and build.
class BayesLearner final : public SkeletonLearner<BayesLearner> {
 public:
  /// @pre cfg.descriptor_length > 0 and cfg.count_scale > 0 and finite (OF_ENFORCE).
  explicit BayesLearner(const BayesConfig& cfg);

  [[nodiscard]] Prediction ask(std::span<const float> descriptor,
                               AskScratch& scratch) const noexcept override;
  [[nodiscard]] std::size_t descriptor_length() const noexcept override {
    return cfg_.descriptor_length;
  }
  [[nodiscard]] const char* kind() const noexcept override { return "bayes"; }
  [[nodiscard]] const BayesConfig& config() const noexcept { return cfg_; }

 private:
  BayesConfig cfg_;
};

extern template class SkeletonLearner<BayesLearner>;

}  // namespace orthoflow::learning
