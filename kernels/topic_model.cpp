#include "kernels/topic_model.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/fnv.hpp"

namespace orthoflow::kernels {

bool TopicModel::consistent() const noexcept {
  if (topics == 0 || words == 0 || word_topic.size() != topics * words ||
      topic_total.size() != topics)
    return false;
  for (std::size_t k = 0; k < topics; ++k) {
    std::uint64_t sum = 0;
    for (std::size_t w = 0; w < words; ++w) sum += word_topic[k * words + w];
    if (sum != topic_total[k]) return false;
  }
  return true;
}

bool LocalTopics::valid() const noexcept {
  return topics > 0 && topics <= MAX_LOCAL_TOPICS && alpha > 0.0 && beta > 0.0 &&
         std::isfinite(alpha) && std::isfinite(beta) && iterations <= MAX_GIBBS_SWEEPS;
}

TopicScratch::TopicScratch(std::size_t topics, std::size_t words, std::size_t max_words)
    : word_topic(topics * words), topic_total(topics), doc_topic(topics), z(max_words), p(topics) {}

std::uint32_t draw_topic(std::uint32_t w, std::span<std::uint32_t> word_topic,
                         std::span<std::uint32_t> topic_total, std::span<std::uint32_t> doc_topic,
                         std::size_t words, double alpha, double beta, std::span<double> p,
                         core::Rng& rng) noexcept {
  const std::size_t topics = topic_total.size();
  const double v_beta = static_cast<double>(words) * beta;
  double total = 0.0;
  for (std::size_t k = 0; k < topics; ++k) {
    const double word_share = (static_cast<double>(word_topic[k * words + w]) + beta) /
                              (static_cast<double>(topic_total[k]) + v_beta);
    total += word_share * (static_cast<double>(doc_topic[k]) + alpha);
    p[k] = total;
  }
  const double u = rng.uniform() * total;
  std::size_t k = 0;
  while (k + 1 < topics && !(u < p[k])) ++k;
  ++word_topic[k * words + w];
  ++topic_total[k];
  ++doc_topic[k];
  return static_cast<std::uint32_t>(k);
}

std::uint64_t document_seed(std::uint64_t model_seed, std::span<const std::uint32_t> doc) noexcept {
  std::uint64_t h = 1469598103934665603ULL ^ model_seed;  // the dictionary ids' basis
  for (const std::uint32_t w : doc) h = core::fnv1a_value(h, w);
  return h;
}

bool infer_topics(std::span<const std::uint32_t> doc, const TopicModel& model,
                  TopicScratch& scratch, std::span<float> theta) noexcept {
  const std::size_t K = model.topics, V = model.words;
  if (theta.size() < K || scratch.word_topic.size() < K * V || scratch.topic_total.size() < K ||
      scratch.doc_topic.size() < K || scratch.p.size() < K || scratch.z.size() < doc.size())
    return false;
  if (std::any_of(doc.begin(), doc.end(), [&](std::uint32_t w) { return w >= V; })) return false;
  // The temporary copy of the counts; the document's words join them.
  std::copy(model.word_topic.begin(), model.word_topic.end(), scratch.word_topic.begin());
  std::copy(model.topic_total.begin(), model.topic_total.end(), scratch.topic_total.begin());
  const std::span<std::uint32_t> wt(scratch.word_topic.data(), K * V);
  const std::span<std::uint32_t> tt(scratch.topic_total.data(), K);
  const std::span<std::uint32_t> dt(scratch.doc_topic.data(), K);
  const std::span<double> p(scratch.p.data(), K);
  std::fill(dt.begin(), dt.end(), 0U);
  core::Rng rng(document_seed(model.seed, doc));
  for (std::size_t i = 0; i < doc.size(); ++i)
    scratch.z[i] = draw_topic(doc[i], wt, tt, dt, V, model.alpha, model.beta, p, rng);
  for (std::uint32_t sweep = 0; sweep < model.iterations; ++sweep) {
    for (std::size_t i = 0; i < doc.size(); ++i) {
      const std::uint32_t w = doc[i], k = scratch.z[i];
      --wt[k * V + w];
      --tt[k];
      --dt[k];
      scratch.z[i] = draw_topic(w, wt, tt, dt, V, model.alpha, model.beta, p, rng);
    }
  }
  const double norm = static_cast<double>(doc.size()) + static_cast<double>(K) * model.alpha;
  for (std::size_t k = 0; k < K; ++k)
    theta[k] = static_cast<float>((static_cast<double>(dt[k]) + model.alpha) / norm);
  return true;
}

}  // namespace orthoflow::kernels
