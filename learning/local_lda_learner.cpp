#include "learning/local_lda_learner.hpp"

#include <algorithm>
#include <cmath>

#include "core/assert.hpp"
#include "learning/detail/learner_common.hpp"
#include "learning/detail/local_lda_category.hpp"

namespace orthoflow::learning {

struct LocalLdaSnapshot {
  std::vector<std::shared_ptr<const LocalLdaCategory>> categories;  // by id
  std::vector<float> icd;  // parallel to categories (NOCD rules)
  float mean_icd = 0.0F;
  std::size_t views = 0;
  std::uint64_t generation = 0;
  CategoryId next_id = 0;
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

Result<void, LearnError> check_counts(DescriptorBatch views, std::size_t max_words,
                                      std::vector<std::uint32_t>& buffer) {
  buffer.resize(max_words);
  for (std::size_t v = 0; v < views.count(); ++v)
    if (!expand_word_counts(views.view(v), buffer)) return err(LearnError::NOT_WORD_COUNTS);
  return {};
}

std::unique_ptr<LocalLdaSnapshot> make_snapshot(std::vector<CategoryPtr> categories,
                                                std::uint64_t generation, CategoryId next_id,
                                                const LocalLdaConfig& cfg) {
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
}

// A batch of word counts, checked, with room for the longest view's words.
struct CheckedCounts {
  DescriptorBatch views;
  std::vector<std::uint32_t> buffer;
};

}  // namespace

template <>
struct LearnerRules<LocalLdaLearner> {
  using Category = LocalLdaCategory;
  using Snapshot = LocalLdaSnapshot;
  using Views = CheckedCounts;
  using L = LocalLdaLearner;

  static Result<Views, LearnError> check(const L& l, DescriptorBatch views) {
    if (auto r = validate_batch(views, l.config().words, true); !r) return err(r.error());
    Views checked{views, {}};
    if (auto r = check_counts(views, l.config().max_words, checked.buffer); !r)
      return err(r.error());
    return checked;
  }
  static CategoryPtr grow(const L& l, const Category* existing, CategoryId id,
                          std::string_view label, Views& counts) {
    auto c = std::make_shared<LocalLdaCategory>(
        existing == nullptr ? empty_category(l.config(), id, label) : *existing);
    for (std::size_t v = 0; v < counts.views.count(); ++v)
      teach_view(*c, counts.views.view(v), counts.buffer);
    settle(*c, l.config());
    return c;
  }
  static Result<CategoryPtr, LearnError> shrink(const L& l, const Category& c, Views& counts) {
    return without_last(c, counts.views, l.config(), counts.buffer);
  }
  // Views are needed: the counts are replayed from them (accumulators alone cannot give topics).
  static Result<void, LearnError> check_restored(const L& l,
                                                 std::span<const RestoredCategory> categories) {
    for (const RestoredCategory& rc : categories)
      if (rc.views.values.empty()) return err(LearnError::NO_VIEWS);
    if (auto r = validate_restored(categories, l.config().words, true); !r) return err(r.error());
    std::vector<std::uint32_t> buffer;
    for (const RestoredCategory& rc : categories)
      if (auto r = check_counts(rc.views, l.config().max_words, buffer); !r) return err(r.error());
    return {};
  }
  static Result<CategoryPtr, LearnError> rebuild(const L& l, const RestoredCategory& rc) {
    Views counts{rc.views, std::vector<std::uint32_t>(l.config().max_words)};
    return grow(l, nullptr, rc.id, rc.label, counts);
  }
  static std::unique_ptr<Snapshot> finish(const L& l, std::vector<CategoryPtr> categories,
                                          std::uint64_t generation, CategoryId next_id) {
    return make_snapshot(std::move(categories), generation, next_id, l.config());
  }
  // Held per category: its K x V counts and a theta row per view (the words and their topics too).
  static std::pair<std::size_t, std::size_t> held(const L&, const Snapshot& s) {
    std::size_t floats = 0;
    for (const CategoryPtr& c : s.categories) {
      floats += c->model.word_topic.size() + c->theta.size();
      for (const auto& v : c->views) floats += 2 * v->words.size();
    }
    return {s.views, floats};
  }
  static CategorySummary summary(const L& l, const Snapshot& s, std::size_t k) {
    const LocalLdaCategory& c = *s.categories[k];
    return CategorySummary{c.id, c.label, c.views.size(),
                           bayes_rule(l.config().decision) ? 0.0F : s.icd[k]};
  }
};

}  // namespace orthoflow::learning

#include "learning/detail/learner_skeleton.inl"

namespace orthoflow::learning {

template class SkeletonLearner<LocalLdaLearner>;

LocalLdaLearner::LocalLdaLearner(const LocalLdaConfig& cfg) : cfg_(cfg) {
  OF_ENFORCE(cfg.words > 0, "LocalLdaConfig::words must be positive");
  OF_ENFORCE(cfg.topics.valid(),
             "LocalLdaConfig: 1..MAX_LOCAL_TOPICS topics, finite alpha and beta > 0, at most "
             "MAX_GIBBS_SWEEPS sweeps");
  OF_ENFORCE(cfg.max_words > 0, "LocalLdaConfig::max_words must be positive");
  enforce_icd_config(cfg.default_icd, cfg.min_icd, cfg.classification_threshold, "LocalLdaConfig");
  OF_ENFORCE(cfg.count_scale > 0.0F && std::isfinite(cfg.count_scale),
             "LocalLdaConfig::count_scale must be > 0");
  start();
}

void LocalLdaLearner::prepare(AskScratch& scratch) const {
  scratch.words.assign(cfg_.max_words, 0);
  scratch.theta.assign(cfg_.topics.topics, 0.0F);
  scratch.topics = kernels::TopicScratch(cfg_.topics.topics, cfg_.words, cfg_.max_words);
}

Prediction LocalLdaLearner::ask(std::span<const float> descriptor,
                                AskScratch& scratch) const noexcept {
  const auto snap = cell().read(scratch.slot_hint);
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

std::vector<float> LocalLdaLearner::view_topics(std::string_view label) const {
  std::size_t hint = 0;
  const auto snap = cell().read(hint);
  for (const CategoryPtr& c : snap->categories)
    if (c->label.view() == label) return c->theta;
  return {};
}

}  // namespace orthoflow::learning
