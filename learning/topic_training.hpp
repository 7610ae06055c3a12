#pragma once
/// @file
/// @brief Fitting the topic layer (thesis chapter 4): LDA over the visual words of a pool of
/// documents by collapsed Gibbs sampling (kernels/topic_model.hpp holds the model, the draw and the
/// inference). The documents are the exploration's object views as word lists; the topics are
/// shared by every category that is taught later (the thesis's "LDA"; its Local LDA, per category,
/// is not built yet). Serial and seeded: the same documents and seed give the same counts on every
/// machine.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/result.hpp"
#include "kernels/topic_model.hpp"
#include "kernels/visual_words.hpp"

namespace orthoflow::learning {

struct TopicFitParams {
  std::size_t topics = 30;        ///< K (the thesis: 30)
  double alpha = 1.0;             ///< the thesis: 1.0
  double beta = 0.1;              ///< the thesis: 0.1
  std::uint32_t iterations = 30;  ///< Gibbs sweeps (the thesis: 30), also used by inference
  std::uint64_t seed = 1;
};

/// @brief Collapsed Gibbs sampling of LDA over @p docs (word ids < @p words): every word drawn a
/// topic in document order, then params.iterations sweeps. Refuses K = 0, V = 0, non-positive or
/// non-finite priors, a word id out of range, or no word at all.
[[nodiscard]] Result<kernels::TopicModel, std::string> fit_lda(
    std::span<const std::vector<std::uint32_t>> docs, std::size_t words,
    const TopicFitParams& params);

/// @brief Gives @p dictionary a topic model fitted on the words of @p views (each view's spin
/// images, rows of dictionary.dims values), and recomputes its id.
[[nodiscard]] Result<void, std::string> add_topics(kernels::VisualDictionary& dictionary,
                                                   std::span<const std::vector<float>> views,
                                                   const TopicFitParams& params);

}  // namespace orthoflow::learning
