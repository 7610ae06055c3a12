#include "learning/bayes_learner.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "learning/detail/learner_common.hpp"

namespace orthoflow::learning {

/// One category model: N_k, the unscaled bin sums s_k (a_k = count_scale * s_k) and log P(x_i |
/// C_k).
struct BayesCategory {
  CategoryId id = NO_CATEGORY;
  Label label;
  std::uint64_t seen = 0;
  std::vector<double> sums;
  std::vector<float> log_p;
};

struct BayesSnapshot {
  std::vector<std::shared_ptr<const BayesCategory>> categories;  // by id
  std::uint64_t total = 0;                                       // N = sum of N_k
  std::uint64_t generation = 0;
  CategoryId next_id = 0;
};

void accumulate_views(DescriptorBatch views, std::span<double> sums) noexcept {
  for (std::size_t v = 0; v < views.count(); ++v) {
    const std::span<const float> x = views.view(v);
    for (std::size_t i = 0; i < sums.size(); ++i) { sums[i] += static_cast<double>(x[i]); }
  }
}

void subtract_views(DescriptorBatch views, std::span<double> sums) noexcept {
  for (std::size_t v = 0; v < views.count(); ++v) {
    const std::span<const float> x = views.view(v);
    for (std::size_t i = 0; i < sums.size(); ++i) {
      // A retraction subtracts what a teach added; rounding must not leave a negative bin.
      sums[i] = std::max(0.0, sums[i] - static_cast<double>(x[i]));
    }
  }
}

namespace {

using CategoryPtr = std::shared_ptr<const BayesCategory>;

// Laplace-smoothed bin probabilities (thesis eq. update_p): P(x_i | C_k) = (a_ki + 1) / sum_j (a_kj
// + 1), with a_ki = count_scale * sums_i; stored as logarithms for the log-likelihood sum.
CategoryPtr make_category(CategoryId id, const Label& label, std::uint64_t seen,
                          std::vector<double> sums, float count_scale) {
  auto c = std::make_shared<BayesCategory>();
  c->id = id;
  c->label = label;
  c->seen = seen;
  c->sums = std::move(sums);
  const double scale = static_cast<double>(count_scale);
  double denominator = 0.0;
  for (const double s : c->sums) { denominator += scale * s + 1.0; }
  c->log_p.resize(c->sums.size());
  for (std::size_t i = 0; i < c->sums.size(); ++i) {
    c->log_p[i] = static_cast<float>(std::log((scale * c->sums[i] + 1.0) / denominator));
  }
  return c;
}

std::unique_ptr<BayesSnapshot> make_snapshot(std::vector<CategoryPtr> categories,
                                             std::uint64_t generation, CategoryId next_id) {
  auto s = std::make_unique<BayesSnapshot>();
  s->categories = std::move(categories);
  s->generation = generation;
  s->next_id = next_id;
  for (const CategoryPtr& c : s->categories) { s->total += c->seen; }
  return s;
}

}  // namespace

template <>
struct LearnerRules<BayesLearner> {
  using Category = BayesCategory;
  using Snapshot = BayesSnapshot;
  using Views = DescriptorBatch;
  using L = BayesLearner;

  static Result<Views, LearnError> check(const L& l, DescriptorBatch views) {
    if (auto r = validate_batch(views, l.descriptor_length(), true); !r) return err(r.error());
    return views;
  }
  // Thesis "Category Initialization and Update": N_k <- N_k + views, a_ki <- a_ki + x'_i.
  static CategoryPtr grow(const L& l, const Category* existing, CategoryId id,
                          std::string_view label, Views& views) {
    std::vector<double> sums =
        existing == nullptr ? std::vector<double>(l.descriptor_length(), 0.0) : existing->sums;
    accumulate_views(views, sums);
    const std::uint64_t seen = (existing == nullptr ? 0 : existing->seen) + views.count();
    return make_category(id, Label::from(label), seen, std::move(sums), l.config().count_scale);
  }
  static Result<CategoryPtr, LearnError> shrink(const L& l, const Category& c, Views& views) {
    if (views.count() > c.seen) return err(LearnError::NOT_LAST_VIEWS);
    const std::uint64_t seen = c.seen - views.count();
    if (seen == 0) return CategoryPtr{};
    std::vector<double> sums = c.sums;
    subtract_views(views, sums);
    return make_category(c.id, c.label, seen, std::move(sums), l.config().count_scale);
  }
  static Result<void, LearnError> check_restored(const L& l,
                                                 std::span<const RestoredCategory> categories) {
    return validate_restored(categories, l.descriptor_length(), true);
  }
  static Result<CategoryPtr, LearnError> rebuild(const L& l, const RestoredCategory& rc) {
    std::vector<double> sums(rc.accumulators.begin(), rc.accumulators.end());
    std::uint64_t seen = rc.seen;
    if (sums.empty()) {
      sums.assign(l.descriptor_length(), 0.0);
      accumulate_views(rc.views, sums);
      seen = rc.views.count();
    }
    return make_category(rc.id, Label::from(rc.label), std::max<std::uint64_t>(seen, 1),
                         std::move(sums), l.config().count_scale);
  }
  static std::unique_ptr<Snapshot> finish(const L&, std::vector<CategoryPtr> categories,
                                          std::uint64_t generation, CategoryId next_id) {
    return make_snapshot(std::move(categories), generation, next_id);
  }
  static std::pair<std::size_t, std::size_t> held(const L& l, const Snapshot& s) {
    return {static_cast<std::size_t>(s.total), s.categories.size() * l.descriptor_length()};
  }
  static CategorySummary summary(const L&, const Snapshot& s, std::size_t k) {
    const BayesCategory& c = *s.categories[k];
    return CategorySummary{c.id, c.label, static_cast<std::size_t>(c.seen), 0.0F};
  }
};

}  // namespace orthoflow::learning

#include "learning/detail/learner_skeleton.inl"

namespace orthoflow::learning {

template class SkeletonLearner<BayesLearner>;

BayesLearner::BayesLearner(const BayesConfig& cfg) : cfg_(cfg) {
  OF_ENFORCE(cfg.descriptor_length > 0, "BayesConfig::descriptor_length must be positive");
  OF_ENFORCE(cfg.count_scale > 0.0F && std::isfinite(cfg.count_scale),
             "BayesConfig::count_scale must be > 0");
  start();
}

Prediction BayesLearner::ask(std::span<const float> descriptor,
                             AskScratch& scratch) const noexcept {
  const auto snap = cell().read(scratch.slot_hint);
  RankedScores ranked(true);
  if (descriptor.size() != cfg_.descriptor_length) {
    return RankedScores::wrong_length(snap->generation);
  }
  const auto n = static_cast<Eigen::Index>(descriptor.size());
  const Eigen::Map<const Eigen::VectorXf> x(descriptor.data(), n);
  const double log_total = std::log(static_cast<double>(snap->total));
  for (const CategoryPtr& c : snap->categories) {
    // log P(C_k) + sum_i y_i log P(x_i | C_k) with y_i = count_scale * x_i (thesis, log-likelihood
    // rule).
    const float dot = x.dot(Eigen::Map<const Eigen::VectorXf>(c->log_p.data(), n));
    const double score = std::log(static_cast<double>(c->seen)) - log_total +
                         static_cast<double>(cfg_.count_scale) * static_cast<double>(dot);
    ranked.offer(static_cast<float>(score), c->id, c->label);
  }
  return ranked.prediction(snap->generation);
}

}  // namespace orthoflow::learning
