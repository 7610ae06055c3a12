#include "learning/local_lda_learner.hpp"

#include <algorithm>
#include <cmath>

#include "core/assert.hpp"
#include "learning/detail/category_writer.hpp"
#include "learning/detail/learner_common.hpp"
#include "learning/snapshot_cell.hpp"

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

struct LocalLdaSnapshot {
  std::vector<std::shared_ptr<const LocalLdaCategory>> categories;  // by id
  std::vector<float> icd;  // parallel to categories (NOCD rules)
  float mean_icd = 0.0F;
  std::size_t views = 0;
  std::uint64_t generation = 0;
  CategoryId next_id = 0;
};

struct LocalLdaLearner::Cell : SnapshotCell<LocalLdaSnapshot> {
  using SnapshotCell::SnapshotCell;
};

std::optional<std::size_t> expand_word_counts(std::span<const float> counts,
                                              std::span<std::uint32_t> out) noexcept {
  std::size_t n = 0;
  for (std::size_t w = 0; w < counts.size(); ++w) {
    const float c = counts[w];
    if (!(c >= 0.0F) || c != std::floor(c) || c > static_cast<float>(out.size() - n))
      return std::nullopt;
    const auto times = static_cast<std::size_t>(c);
    std::fill_n(out.begin() + static_cast<std::ptrdiff_t>(n), times, static_cast<std::uint32_t>(w));
    n += times;
  }
  if (n == 0) return std::nullopt;
  return n;
}

namespace {

bool bayes_rule(LocalLdaDecision d) noexcept {
  return d == LocalLdaDecision::LIKELIHOOD || d == LocalLdaDecision::TOPIC_HISTOGRAM;
}

using CategoryPtr = std::shared_ptr<const LocalLdaCategory>;

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

Result<void, LearnError> check_counts(DescriptorBatch views, std::size_t max_words,
                                      std::vector<std::uint32_t>& buffer) {
  buffer.resize(max_words);
  for (std::size_t v = 0; v < views.count(); ++v)
    if (!expand_word_counts(views.view(v), buffer)) return err(LearnError::NOT_WORD_COUNTS);
  return {};
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

// Log P(k | C) from the theta sums (BayesLearner's Laplace rule with the count scale).
void update_log_p(LocalLdaCategory& c, float count_scale) {
  const double scale = static_cast<double>(count_scale);
  double denominator = 0.0;
  for (const double s : c.theta_sum) denominator += scale * s + 1.0;
  c.log_p.resize(c.theta_sum.size());
  for (std::size_t k = 0; k < c.theta_sum.size(); ++k)
    c.log_p[k] = static_cast<float>(std::log((scale * c.theta_sum[k] + 1.0) / denominator));
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

auto finisher(const LocalLdaConfig& cfg) {
  return [&cfg](std::vector<CategoryPtr> categories, std::uint64_t generation, CategoryId next_id) {
    auto s = std::make_unique<LocalLdaSnapshot>();
    s->categories = std::move(categories);
    s->generation = generation;
    s->next_id = next_id;
    // ICD as InstanceLearner forms it, between the views' topic histograms.
    std::vector<PairSum> sums;
    for (const CategoryPtr& c : s->categories) {
      s->views += c->views.size();
      sums.push_back(PairSum{c->views.size(), c->pair_sum});
    }
    s->mean_icd = category_icds(sums, cfg.min_icd, cfg.default_icd, s->icd);
    return s;
  };
}

// The category without its last views.count() views, which must be @p views; null when none
// would be left.
Result<CategoryPtr, LearnError> without_last(const LocalLdaCategory& c, DescriptorBatch views,
                                             const LocalLdaConfig& cfg,
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
  if (keep == 0) return CategoryPtr{};
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
  return CategoryPtr{std::move(next)};
}

}  // namespace

LocalLdaLearner::LocalLdaLearner(const LocalLdaConfig& cfg) : cfg_(cfg) {
  OF_ENFORCE(cfg.words > 0, "LocalLdaConfig::words must be positive");
  OF_ENFORCE(cfg.topics.valid(),
             "LocalLdaConfig: 1..MAX_LOCAL_TOPICS topics, finite alpha and beta > 0, at most "
             "MAX_GIBBS_SWEEPS sweeps");
  OF_ENFORCE(cfg.max_words > 0, "LocalLdaConfig::max_words must be positive");
  enforce_icd_config(cfg.default_icd, cfg.min_icd, cfg.classification_threshold, "LocalLdaConfig");
  OF_ENFORCE(cfg.count_scale > 0.0F && std::isfinite(cfg.count_scale),
             "LocalLdaConfig::count_scale must be > 0");
  cell_ = std::make_unique<Cell>(finisher(cfg_)({}, 0, 0));
}

LocalLdaLearner::~LocalLdaLearner() = default;

Result<CategoryId, LearnError> LocalLdaLearner::teach(std::string_view label,
                                                      DescriptorBatch views) {
  if (auto r = validate_label(label); !r) return err(r.error());
  if (auto r = validate_batch(views, cfg_.words, true); !r) return err(r.error());
  std::vector<std::uint32_t> buffer;
  if (auto r = check_counts(views, cfg_.max_words, buffer); !r) return err(r.error());
  auto make = [&](const LocalLdaCategory* existing, CategoryId id) {
    auto c = std::make_shared<LocalLdaCategory>(
        existing == nullptr ? empty_category(cfg_, id, label) : *existing);
    for (std::size_t v = 0; v < views.count(); ++v) teach_view(*c, views.view(v), buffer);
    settle(*c, cfg_);
    return CategoryPtr{std::move(c)};
  };
  return upsert_category(writer_, *cell_, label, make, finisher(cfg_));
}

void LocalLdaLearner::prepare(AskScratch& scratch) const {
  scratch.words.assign(cfg_.max_words, 0);
  scratch.theta.assign(cfg_.topics.topics, 0.0F);
  scratch.topics = kernels::TopicScratch(cfg_.topics.topics, cfg_.words, cfg_.max_words);
}

Prediction LocalLdaLearner::ask(std::span<const float> descriptor,
                                AskScratch& scratch) const noexcept {
  const auto snap = cell_->read(scratch.slot_hint);
  const std::size_t K = cfg_.topics.topics;
  const bool bayes = bayes_rule(cfg_.decision);
  RankedScores ranked(bayes);
  if (descriptor.size() != cfg_.words || scratch.theta.size() < K ||
      scratch.words.size() < cfg_.max_words)
    return RankedScores::wrong_length(snap->generation);
  const auto n = expand_word_counts(descriptor, scratch.words);
  if (!n) return RankedScores::wrong_length(snap->generation);
  const std::span<const std::uint32_t> words(scratch.words.data(), *n);
  const std::span<float> theta(scratch.theta.data(), K);
  const double log_total = std::log(static_cast<double>(snap->views));
  for (std::size_t k = 0; k < snap->categories.size(); ++k) {
    const LocalLdaCategory& c = *snap->categories[k];
    // theta_T^(c): the target in this category's topics, against a temporary copy of its counts.
    if (!kernels::infer_topics(words, c.model, scratch.topics, theta))
      return RankedScores::wrong_length(snap->generation);
    double score = 0.0;
    if (cfg_.decision == LocalLdaDecision::LIKELIHOOD) {
      score = std::log(static_cast<double>(c.views.size())) - log_total +
              log_likelihood(words, theta, c.model);
    } else if (cfg_.decision == LocalLdaDecision::TOPIC_HISTOGRAM) {
      double dot = 0.0;
      for (std::size_t t = 0; t < K; ++t)
        dot += static_cast<double>(theta[t]) * static_cast<double>(c.log_p[t]);
      score = std::log(static_cast<double>(c.views.size())) - log_total +
              static_cast<double>(cfg_.count_scale) * dot;
    } else {
      const std::span<const float> rows(c.theta);
      double best = std::numeric_limits<double>::infinity(), sum = 0.0;
      for (std::size_t r = 0; r < c.views.size(); ++r) {
        const double d = chi_squared(theta, rows.subspan(r * K, K));
        best = std::min(best, d);
        sum += d;
      }
      const double mean = sum / static_cast<double>(c.views.size());
      const auto icd = static_cast<double>(snap->icd[k]);
      score = cfg_.decision == LocalLdaDecision::NEAREST ? best
              : cfg_.decision == LocalLdaDecision::NOCD_1
                  ? best / icd
                  : 2.0 * mean / (icd + static_cast<double>(snap->mean_icd));
    }
    ranked.offer(static_cast<float>(score), c.id, c.label);
  }
  Prediction p = ranked.prediction(snap->generation);
  return bayes ? p : with_threshold(p, cfg_.classification_threshold);
}

Result<void, LearnError> LocalLdaLearner::forget(std::string_view label) {
  return erase_category(writer_, *cell_, label, finisher(cfg_));
}

Result<void, LearnError> LocalLdaLearner::retract(std::string_view label, DescriptorBatch views) {
  if (auto r = validate_batch(views, cfg_.words, true); !r) return err(r.error());
  std::vector<std::uint32_t> buffer;
  if (auto r = check_counts(views, cfg_.max_words, buffer); !r) return err(r.error());
  auto make = [&](const LocalLdaCategory& c) { return without_last(c, views, cfg_, buffer); };
  return shrink_category(writer_, *cell_, label, make, finisher(cfg_));
}

Result<void, LearnError> LocalLdaLearner::restore(std::span<const RestoredCategory> categories,
                                                  CategoryId next_id) {
  // Views are needed: the counts are replayed from them (accumulators alone cannot give topics).
  for (const RestoredCategory& rc : categories)
    if (rc.views.values.empty()) return err(LearnError::NO_VIEWS);
  if (auto r = validate_restored(categories, cfg_.words, true); !r) return err(r.error());
  std::vector<std::uint32_t> buffer;
  for (const RestoredCategory& rc : categories)
    if (auto r = check_counts(rc.views, cfg_.max_words, buffer); !r) return err(r.error());
  std::vector<CategoryPtr> next;
  for (const RestoredCategory& rc : categories) {
    auto c = std::make_shared<LocalLdaCategory>(empty_category(cfg_, rc.id, rc.label));
    for (std::size_t v = 0; v < rc.views.count(); ++v) teach_view(*c, rc.views.view(v), buffer);
    settle(*c, cfg_);
    next.push_back(std::move(c));
    next_id = std::max(next_id, rc.id + 1);
  }
  replace_categories(writer_, *cell_, std::move(next), next_id, finisher(cfg_));
  return {};
}

LearnerStats LocalLdaLearner::stats() const noexcept {
  std::size_t hint = 0;
  const auto snap = cell_->read(hint);
  // Held per category: its K x V counts and a theta row per view (the words and their topics too).
  std::size_t held = 0;
  for (const CategoryPtr& c : snap->categories) {
    held += c->model.word_topic.size() + c->theta.size();
    for (const auto& v : c->views) held += 2 * v->words.size();
  }
  return LearnerStats{snap->categories.size(), snap->views, held, snap->generation,
                      cell_->retired_pending()};
}

std::vector<CategorySummary> LocalLdaLearner::categories() const {
  std::size_t hint = 0;
  const auto snap = cell_->read(hint);
  std::vector<CategorySummary> out;
  for (std::size_t k = 0; k < snap->categories.size(); ++k) {
    const LocalLdaCategory& c = *snap->categories[k];
    out.push_back(CategorySummary{c.id, c.label, c.views.size(),
                                  bayes_rule(cfg_.decision) ? 0.0F : snap->icd[k]});
  }
  return out;
}

std::vector<float> LocalLdaLearner::view_topics(std::string_view label) const {
  std::size_t hint = 0;
  const auto snap = cell_->read(hint);
  for (const CategoryPtr& c : snap->categories)
    if (c->label.view() == label) return c->theta;
  return {};
}

}  // namespace orthoflow::learning
