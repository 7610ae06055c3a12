// A Local LDA category's counts, views and theta rows (learning/detail/local_lda_category.hpp).
#include "learning/detail/local_lda_category.hpp"

#include <algorithm>
#include <cmath>

#include "core/assert.hpp"

namespace orthoflow::learning {

namespace {

// Log P(k | C) from the theta sums (BayesLearner's Laplace rule with the count scale).
void update_log_p(LocalLdaCategory& c, float count_scale) {
  const double scale = static_cast<double>(count_scale);
  double denominator = 0.0;
  for (const double s : c.theta_sum) denominator += scale * s + 1.0;
  c.log_p.resize(c.theta_sum.size());
  for (std::size_t k = 0; k < c.theta_sum.size(); ++k)
    c.log_p[k] = static_cast<float>(std::log((scale * c.theta_sum[k] + 1.0) / denominator));
}

// The pair sum and the theta sums of a category's rows, from scratch.
void sum_rows(LocalLdaCategory& c) {
  const std::size_t K = c.model.topics, n = c.views.size();
  c.pair_sum = 0.0;
  std::fill(c.theta_sum.begin(), c.theta_sum.end(), 0.0);
  const std::span<const float> rows(c.theta);
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t k = 0; k < K; ++k) c.theta_sum[k] += rows[a * K + k];
    for (std::size_t b = 0; b < a; ++b)
      c.pair_sum += chi_squared(rows.subspan(a * K, K), rows.subspan(b * K, K));
  }
}

// Every view's theta again, described in the category's current topics exactly as a target is
// (against a temporary copy of the counts), so that stored views and targets share one topic
// space; then the pair sum and the theta sums. Depends only on the counts and the views' words.
void redescribe(LocalLdaCategory& c) {
  const std::size_t K = c.model.topics, V = c.model.words, n = c.views.size();
  std::size_t longest = 0;
  for (const auto& v : c.views) longest = std::max(longest, v->words.size());
  kernels::TopicScratch scratch(K, V, longest);
  for (std::size_t r = 0; r < n; ++r)
    OF_ENFORCE(kernels::infer_topics(c.views[r]->words, c.model, scratch,
                                     std::span<float>(c.theta).subspan(r * K, K)),
               "Local LDA: a taught view was refused by the sampler");
  sum_rows(c);
}

}  // namespace

// PIPELINE.md section 7: topic histograms are compared by chi-squared (kernels/distance.hpp's
// definition, sum (a - b)^2 / (a + b), in double; theta is never 0, alpha > 0).
double chi_squared(std::span<const float> a, std::span<const float> b) noexcept {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double x = static_cast<double>(a[i]), y = static_cast<double>(b[i]);
    if (x + y > 0.0) sum += (x - y) * (x - y) / (x + y);
  }
  return sum;
}

// log p(w_T | c) = sum_i log sum_k theta_k phi_k,w_i, phi_kw = (n_kw + beta) / (n_k + V beta):
// how likely the category's topic model makes the target's words, with the target's topics in it.
double log_likelihood(std::span<const std::uint32_t> words, std::span<const float> theta,
                      const kernels::TopicModel& m) noexcept {
  const std::size_t K = m.topics, V = m.words;
  const double v_beta = static_cast<double>(V) * m.beta;
  double sum = 0.0;
  for (const std::uint32_t w : words) {
    double p = 0.0;
    for (std::size_t k = 0; k < K; ++k)
      p += static_cast<double>(theta[k]) * (static_cast<double>(m.word_topic[k * V + w]) + m.beta) /
           (static_cast<double>(m.topic_total[k]) + v_beta);
    sum += std::log(p);
  }
  return sum;
}

// Thesis: the new instance's words are drawn topics against the category's counts, which then
// keep them (the incremental update); its theta joins the category's rows (settle() then derives
// what the decision rules need). @p buffer: room for max_words words.
void teach_view(LocalLdaCategory& c, std::span<const float> counts,
                std::span<std::uint32_t> buffer) {
  const std::size_t K = c.model.topics, V = c.model.words;
  auto view = std::make_shared<LocalLdaView>();
  const std::size_t n = expand_word_counts(counts, buffer).value();
  view->words.assign(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
  kernels::TopicScratch scratch(K, V, n);
  std::vector<float> theta(K);
  OF_ENFORCE(kernels::infer_topics(view->words, c.model, scratch, theta),
             "Local LDA: a checked view was refused by the sampler");
  std::copy_n(scratch.word_topic.begin(), K * V, c.model.word_topic.begin());
  std::copy_n(scratch.topic_total.begin(), K, c.model.topic_total.begin());
  view->z.assign(scratch.z.begin(), scratch.z.begin() + static_cast<std::ptrdiff_t>(n));
  c.theta.insert(c.theta.end(), theta.begin(), theta.end());
  c.views.push_back(std::move(view));
}

// After a teach, retract or restore: the views' theta (described again, or as taught), their pair
// and theta sums, and log P(k | C).
void settle(LocalLdaCategory& c, const LocalLdaConfig& cfg) {
  if (cfg.redescribe) {
    redescribe(c);
  } else {
    sum_rows(c);
  }
  update_log_p(c, cfg.count_scale);
}

LocalLdaCategory empty_category(const LocalLdaConfig& cfg, CategoryId id, std::string_view label) {
  LocalLdaCategory c;
  c.id = id;
  c.label = Label::from(label);
  const kernels::LocalTopics& t = cfg.topics;
  c.model.topics = t.topics;
  c.model.words = cfg.words;
  c.model.alpha = t.alpha;
  c.model.beta = t.beta;
  c.model.iterations = t.iterations;
  c.model.seed = t.seed;
  c.model.word_topic.assign(t.topics * cfg.words, 0);
  c.model.topic_total.assign(t.topics, 0);
  c.theta_sum.assign(t.topics, 0.0);
  return c;
}

// The category without its last views.count() views, which must be @p views; null when none
// would be left.
Result<std::shared_ptr<const LocalLdaCategory>, LearnError> without_last(
    const LocalLdaCategory& c, DescriptorBatch views, const LocalLdaConfig& cfg,
    std::span<std::uint32_t> words) {
  const std::size_t n = views.count(), K = c.model.topics, V = c.model.words;
  if (n > c.views.size()) return err(LearnError::NOT_LAST_VIEWS);
  const std::size_t keep = c.views.size() - n;
  for (std::size_t v = 0; v < n; ++v) {
    const std::size_t count = expand_word_counts(views.view(v), words).value();
    const std::vector<std::uint32_t>& taught = c.views[keep + v]->words;
    if (!std::equal(taught.begin(), taught.end(), words.begin(),
                    words.begin() + static_cast<std::ptrdiff_t>(count)) ||
        taught.size() != count)
      return err(LearnError::NOT_LAST_VIEWS);
  }
  if (keep == 0) return std::shared_ptr<const LocalLdaCategory>{};
  auto next = std::make_shared<LocalLdaCategory>(empty_category(cfg, c.id, c.label.view()));
  next->model.word_topic = c.model.word_topic;
  next->model.topic_total = c.model.topic_total;
  for (std::size_t v = keep; v < c.views.size(); ++v) {
    const LocalLdaView& gone = *c.views[v];
    for (std::size_t i = 0; i < gone.words.size(); ++i) {
      --next->model.word_topic[gone.z[i] * V + gone.words[i]];
      --next->model.topic_total[gone.z[i]];
    }
  }
  next->views.assign(c.views.begin(), c.views.begin() + static_cast<std::ptrdiff_t>(keep));
  next->theta.assign(c.theta.begin(), c.theta.begin() + static_cast<std::ptrdiff_t>(keep * K));
  settle(*next, cfg);
  return std::shared_ptr<const LocalLdaCategory>{std::move(next)};
}

}  // namespace orthoflow::learning
