#pragma once
/// @file
/// @brief A Local LDA category (learning/local_lda_learner.hpp): its own topic model over its
/// views' words, the views with the topic each word was drawn, their theta rows, and what the
/// decision rules derive from them. The thesis's incremental update and its inverse (retract) live
/// here; the learner decides with them. Internal to learning/.
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "kernels/topic_model.hpp"
#include "learning/local_lda_learner.hpp"

namespace orthoflow::learning {

/// One taught view: its words (increasing id) and the topic each was drawn.
struct LocalLdaView {
  std::vector<std::uint32_t> words;
  std::vector<std::uint32_t> z;
};

/// One category: its topic model (n_kw, n_k over its own views), its views, their theta rows and
/// what the decision rules need of them.
struct LocalLdaCategory {
  CategoryId id = NO_CATEGORY;
  Label label;
  kernels::TopicModel model;
  std::vector<std::shared_ptr<const LocalLdaView>> views;
  std::vector<float> theta;       // views x K, row-major
  std::vector<double> theta_sum;  // K: the sum of the rows (TOPIC_HISTOGRAM)
  std::vector<float> log_p;       // K: log P(k | C) (TOPIC_HISTOGRAM)
  double pair_sum = 0.0;          // sum over unordered pairs of rows of their chi-squared
};

/// @brief Chi-squared between two topic histograms (PIPELINE.md section 7), in double.
[[nodiscard]] double chi_squared(std::span<const float> a, std::span<const float> b) noexcept;
/// @brief log p(w_T | c): how likely category model @p m makes @p words with topics @p theta.
[[nodiscard]] double log_likelihood(std::span<const std::uint32_t> words,
                                    std::span<const float> theta,
                                    const kernels::TopicModel& m) noexcept;
/// @brief Adds one view of word @p counts to @p c (thesis: the incremental update); @p buffer has
/// room for max_words words. @pre the counts passed expand_word_counts.
void teach_view(LocalLdaCategory& c, std::span<const float> counts,
                std::span<std::uint32_t> buffer);
/// @brief After a teach, retract or restore: the views' theta, their sums and log P(k | C).
void settle(LocalLdaCategory& c, const LocalLdaConfig& cfg);
/// @brief A category with no view yet, its model sized by @p cfg.
[[nodiscard]] LocalLdaCategory empty_category(const LocalLdaConfig& cfg, CategoryId id,
                                              std::string_view label);
/// @brief The category without its last views.count() views, which must be @p views
/// (NOT_LAST_VIEWS); null when none would be left. @p words: room for max_words words.
[[nodiscard]] Result<std::shared_ptr<const LocalLdaCategory>, LearnError> without_last(
    const LocalLdaCategory& c, DescriptorBatch views, const LocalLdaConfig& cfg,
    std::span<std::uint32_t> words);

}  // namespace orthoflow::learning
