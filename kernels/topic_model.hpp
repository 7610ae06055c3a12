#pragma once
/// @file
/// @brief The topic layer (thesis chapter 4): LDA over visual words, with symmetric Dirichlet
/// priors alpha and beta, fitted by collapsed Gibbs sampling (learning/topic_training.hpp), and the
/// inference of one view's topic histogram against the fitted counts. Each word w of a document d
/// with topic z draws its next topic from
///   p(z = k) ~ (n_kw + beta) / (n_k + V beta) * (n_dk + alpha)
/// with its own assignment taken out of every count first; then
///   theta_dk = (n_dk + alpha) / (N_d + K alpha),  phi_kw = (n_kw + beta) / (n_k + V beta).
/// Inference samples the view's words against a temporary copy of the counts (the view's own words
/// added to it), as chapter 4 describes, and leaves the model unchanged.
///
/// Deterministic: the draws come from core::Rng seeded from the model's seed and the document's
/// words, the probabilities are summed in topic order in double precision without fused
/// multiply-adds, so a view gets the same histogram on any thread, on x86 and on ARM.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/rng.hpp"

namespace orthoflow::kernels {

/// @brief A fitted topic model over a dictionary's V words.
struct TopicModel {
  std::size_t topics = 0;                  ///< K
  std::size_t words = 0;                   ///< V
  double alpha = 1.0;                      ///< the thesis: 1.0
  double beta = 0.1;                       ///< the thesis: 0.1
  std::uint32_t iterations = 30;           ///< Gibbs sweeps (the thesis: 30), fitting and inference
  std::uint64_t seed = 1;                  ///< of every draw
  std::vector<std::uint32_t> word_topic;   ///< n_kw at [k * V + w]
  std::vector<std::uint32_t> topic_total;  ///< n_k
  [[nodiscard]] bool consistent() const noexcept;  ///< sizes agree and n_k = sum over w of n_kw
};

/// @brief Most topics a Local LDA category may have (its counts are K x V per category).
inline constexpr std::size_t MAX_LOCAL_TOPICS = 1024;
/// @brief Most Gibbs sweeps a specification may ask for (the thesis: 30).
inline constexpr std::uint32_t MAX_GIBBS_SWEEPS = 10000;

/// @brief The priors and sampling of topics learned per category (the thesis's Local LDA, chapter
/// 4: its default K = 30 with 90 words, alpha 1.0, beta 0.1, 30 Gibbs sweeps).
struct LocalTopics {
  std::size_t topics = 30;  ///< K, in every category
  double alpha = 1.0;
  double beta = 0.1;
  std::uint32_t iterations = 30;  ///< Gibbs sweeps of a taught view and of a target
  std::uint64_t seed = 1;         ///< of every draw (mixed with the view's words)
  [[nodiscard]] bool operator==(const LocalTopics&) const noexcept = default;
  /// @brief 1..MAX_LOCAL_TOPICS topics, finite alpha and beta > 0, at most MAX_GIBBS_SWEEPS sweeps:
  /// the one rule the specification, a store's schema and the learner check.
  [[nodiscard]] bool valid() const noexcept;
};

/// @brief Scratch of topic inference, sized once for a model and documents of up to max_words.
struct TopicScratch {
  TopicScratch() = default;
  TopicScratch(std::size_t topics, std::size_t words, std::size_t max_words);
  std::vector<std::uint32_t> word_topic, topic_total, doc_topic, z;
  std::vector<double> p;
};

/// @brief One Gibbs sweep's draw for word @p w currently in no count: its new topic, added to the
/// counts. Shared by fitting and inference (one rule).
std::uint32_t draw_topic(std::uint32_t w, std::span<std::uint32_t> word_topic,
                         std::span<std::uint32_t> topic_total, std::span<std::uint32_t> doc_topic,
                         std::size_t words, double alpha, double beta, std::span<double> p,
                         core::Rng& rng) noexcept;

/// @brief The seed of a document's draws: the model's seed mixed with its words (FNV-1a).
[[nodiscard]] std::uint64_t document_seed(std::uint64_t model_seed,
                                          std::span<const std::uint32_t> doc) noexcept;

/// @brief theta of the document @p doc (word ids < model.words) against @p model, written to
/// @p theta (model.topics values summing to 1). An empty document gives the prior (1 / K each).
/// @return false when the scratch is too small for the model or the document, or a word id is out
/// of range (nothing written). @note Allocation-free with its scratch; deterministic.
[[nodiscard]] bool infer_topics(std::span<const std::uint32_t> doc, const TopicModel& model,
                                TopicScratch& scratch, std::span<float> theta) noexcept;

}  // namespace orthoflow::kernels
