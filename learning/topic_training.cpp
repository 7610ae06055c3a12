#include "learning/topic_training.hpp"

#include <cmath>

namespace orthoflow::learning {

Result<kernels::TopicModel, std::string> fit_lda(std::span<const std::vector<std::uint32_t>> docs,
                                                 std::size_t words, const TopicFitParams& params) {
  if (params.topics == 0 || words == 0)
    return err(std::string("topics: K and the dictionary's words must be at least 1"));
  if (!(params.alpha > 0.0) || !(params.beta > 0.0) || !std::isfinite(params.alpha) ||
      !std::isfinite(params.beta))
    return err(std::string("topics: alpha and beta must be finite and > 0"));
  std::size_t total = 0;
  for (const auto& d : docs) {
    for (const std::uint32_t w : d)
      if (w >= words) return err("topics: word " + std::to_string(w) + " is past the dictionary");
    total += d.size();
  }
  if (total == 0) return err(std::string("topics: no word to fit on"));
  kernels::TopicModel m;
  m.topics = params.topics;
  m.words = words;
  m.alpha = params.alpha;
  m.beta = params.beta;
  m.iterations = params.iterations;
  m.seed = params.seed;
  m.word_topic.assign(m.topics * words, 0);
  m.topic_total.assign(m.topics, 0);
  std::vector<std::vector<std::uint32_t>> z(docs.size()), doc_topic(docs.size());
  std::vector<double> p(m.topics);
  core::Rng rng(params.seed);
  for (std::size_t d = 0; d < docs.size(); ++d) {
    doc_topic[d].assign(m.topics, 0);
    z[d].resize(docs[d].size());
    for (std::size_t i = 0; i < docs[d].size(); ++i)
      z[d][i] = kernels::draw_topic(docs[d][i], m.word_topic, m.topic_total, doc_topic[d], words,
                                    m.alpha, m.beta, p, rng);
  }
  for (std::uint32_t sweep = 0; sweep < params.iterations; ++sweep) {
    for (std::size_t d = 0; d < docs.size(); ++d) {
      for (std::size_t i = 0; i < docs[d].size(); ++i) {
        const std::uint32_t w = docs[d][i], k = z[d][i];
        --m.word_topic[k * words + w];
        --m.topic_total[k];
        --doc_topic[d][k];
        z[d][i] = kernels::draw_topic(w, m.word_topic, m.topic_total, doc_topic[d], words, m.alpha,
                                      m.beta, p, rng);
      }
    }
  }
  return m;
}

Result<void, std::string> add_topics(kernels::VisualDictionary& dictionary,
                                     std::span<const std::vector<float>> views,
                                     const TopicFitParams& params) {
  std::vector<std::vector<std::uint32_t>> docs(views.size());
  std::vector<float> scratch(dictionary.words);
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (dictionary.dims == 0 || views[v].size() % dictionary.dims != 0)
      return err("topics: view " + std::to_string(v) + " is not whole spin images");
    docs[v].resize(views[v].size() / dictionary.dims);
    docs[v].resize(kernels::assign_words(views[v], dictionary.view(), scratch, docs[v]));
  }
  auto model = fit_lda(docs, dictionary.words, params);
  if (!model) return err(model.error());
  dictionary.topics = std::move(model.value());
  dictionary.id = kernels::dictionary_id(dictionary);
  return {};
}

}  // namespace orthoflow::learning
