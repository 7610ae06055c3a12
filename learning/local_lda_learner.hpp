#pragma once
/// @file
/// @brief Local LDA (thesis chapter 4, "Local LDA", and chapter 5; Kasaei et al., TPAMI 2019):
/// every category learns topics of its own over the dictionary's words, and a view is described in
/// each category's topic space.
/// - A descriptor is a view's word counts (DescriptorKind::LOCAL_LDA: V whole numbers; the words
///   are taken in increasing id, each as often as it was counted).
/// - Teach (the incremental update): each new view's words are drawn topics by collapsed Gibbs
///   sampling against the category's counts n_kw and n_k with the view's own words in them
///   (kernels::infer_topics, the same sweeps as a target), and the counts keep them. The views
///   taught before keep their topics, so their theta_o = (n_ok + alpha) / (N_o + K alpha) stays.
/// - Ask: the target is described in every category's topics against a temporary copy of that
///   category's counts (theta_T^(c)), then
///   - NEAREST: score = min over the category's views of chi2(theta_T^(c), theta_o) (chi-squared,
///   PIPELINE.md section 7);
///   - NOCD_1 / NOCD_2: approach I / II's normalised distances, with each category's ICD measured
///     between its views' theta (InstanceLearner's rules, in the category's own space);
///   - LIKELIHOOD (model-based, the default of "bayes"): score = log P(C) + log p(w_T | c), the
///     category's topic model's probability of the target's words, sum_i log sum_k
///     theta_T^(c)_k phi^(c)_k,w_i with phi_kw = (n_kw + beta) / (n_k + V beta);
///   - TOPIC_HISTOGRAM: BayesLearner's naive Bayes over topic histograms, score = log P(C) +
///     s sum_k theta_T^(c)_k log P(k | C), P(k | C) = (s a_k + 1) / sum_j (s a_j + 1), a = the
///     sum of the category's theta_o, s = count_scale. Each category scores a histogram of its
///     own topics, so the scores are not comparable between categories: measured far below
///     LIKELIHOOD (docs/EVALUATION.md), kept to show it.
/// Deterministic: the draws are seeded from the specification's seed and the view's words, so the
/// same teaching gives the same counts on any thread, on x86 and ARM; restore() replays the views
/// in their order and gets the same state back. Cost: ask() samples the target once per category
/// (K x V counts copied, iterations x words x K draws), so it grows with the categories.
#include <limits>
#include <optional>

#include "kernels/topic_model.hpp"
#include "learning/learner_skeleton.hpp"

namespace orthoflow::learning {

/// @brief How a Local LDA learner decides among categories.
enum class LocalLdaDecision : std::uint8_t {
  NEAREST,         ///< instance-based, plain nearest view (chi-squared)
  NOCD_1,          ///< instance-based, approach I
  NOCD_2,          ///< instance-based, approach II
  LIKELIHOOD,      ///< model-based: the category's topic model's likelihood of the words
  TOPIC_HISTOGRAM  ///< model-based: naive Bayes over the topic histogram
};

/// @brief Plain configuration of LocalLdaLearner (validated by the constructor: OF_ENFORCE).
struct LocalLdaConfig {
  std::size_t words = 90;         ///< V: the dictionary's words (the descriptor's length)
  kernels::LocalTopics topics{};  ///< K, alpha, beta, sweeps and seed of every category
  std::size_t max_words = 20000;  ///< most words (spin images) in one view
  LocalLdaDecision decision = LocalLdaDecision::NEAREST;
  float classification_threshold =
      std::numeric_limits<float>::infinity();  ///< CT of the distance rules; infinity = never
  float default_icd = 0.1F;                    ///< ICD while no category has two views (NOCD rules)
  float min_icd = 1e-6F;                       ///< floor of every ICD
  float count_scale = 100.0F;  ///< TOPIC_HISTOGRAM: pseudo-counts per topic histogram
  /// After each teach, describe every view of the category again in its current topics (as a
  /// target is); false: a view keeps the theta it was taught with (the thesis's letter).
  bool redescribe = true;
};

/// @brief The word ids of a view's counts, in increasing id (each repeated as counted), into @p
/// out. @return how many, or std::nullopt when a count is not a whole number >= 0 or the total is
/// 0 or more than out.size().
[[nodiscard]] std::optional<std::size_t> expand_word_counts(std::span<const float> counts,
                                                            std::span<std::uint32_t> out) noexcept;

/// @brief Local LDA learner, see file comment. Thread-safe as described in learning/learner.hpp.
class LocalLdaLearner final : public SkeletonLearner<LocalLdaLearner> {
 public:
  /// @pre cfg.words > 0, topics within kernels::MAX_LOCAL_TOPICS, positive finite priors,
  /// max_words > 0, positive ICDs and count scale (OF_ENFORCE).
  explicit LocalLdaLearner(const LocalLdaConfig& cfg);

  /// @pre prepare(scratch) was called (else: unknown, score NaN).
  [[nodiscard]] Prediction ask(std::span<const float> descriptor,
                               AskScratch& scratch) const noexcept override;
  void prepare(AskScratch& scratch) const override;
  [[nodiscard]] std::size_t descriptor_length() const noexcept override { return cfg_.words; }
  [[nodiscard]] const char* kind() const noexcept override {
    return cfg_.decision == LocalLdaDecision::LIKELIHOOD        ? "local-lda-likelihood"
           : cfg_.decision == LocalLdaDecision::TOPIC_HISTOGRAM ? "local-lda-topic-bayes"
                                                                : "local-lda-instance";
  }
  [[nodiscard]] const LocalLdaConfig& config() const noexcept { return cfg_; }
  /// @brief theta of category @p label's views in its topics (rows of K), for tests and tools;
  /// empty when no category has that label. @note Allocates.
  [[nodiscard]] std::vector<float> view_topics(std::string_view label) const;

 private:
  LocalLdaConfig cfg_;
};

extern template class SkeletonLearner<LocalLdaLearner>;

}  // namespace orthoflow::learning
