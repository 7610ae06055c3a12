#include "learning/instance_learner.hpp"

#include <algorithm>
#include <cmath>

#include "kernels/distance.hpp"
#include "learning/detail/learner_common.hpp"

namespace orthoflow::learning {

/// One category: its views as a dims x stride structure-of-arrays matrix (columns count..stride are
/// zero) and the sum of its pairwise distances, kept so that ICD is updated in O(new views x count)
/// per teach.
struct InstanceCategory {
  CategoryId id = NO_CATEGORY;
  Label label;
  std::size_t count = 0;
  std::size_t stride =
      0;  // count rounded up to COLUMN_PAD: zero columns keep the kernel in its SIMD body
  std::vector<float> soa;
  double pair_sum = 0.0;  // sum over unordered pairs {U, V}, U != V, of D(U, V)
};

struct InstanceSnapshot {
  std::vector<std::shared_ptr<const InstanceCategory>> categories;  // by id
  std::vector<float> icd;  // ICD in use, parallel to categories
  float mean_icd = 0.0F;   // mean of icd (approach II)
  std::size_t views = 0;
  std::uint64_t generation = 0;
  CategoryId next_id = 0;
};

namespace {

using CategoryPtr = std::shared_ptr<const InstanceCategory>;

// kernels::distances runs SIMD across columns (16 lanes with AVX-512) and finishes with a scalar
// tail, so a 10-view category would be all tail. Padding columns to a multiple of 16 lets ask()
// compute the zero columns too and ignore them: 1.6x the arithmetic of a 10-view category, at SIMD
// speed.
constexpr std::size_t COLUMN_PAD = 16;

// A new category holding @p base's views followed by @p views; every new view adds its distances to
// all earlier views to pair_sum (thesis: ICD_n <- ICD(C_n) after C_n <- C_{n-1} U {O_n}).
CategoryPtr extend(const InstanceCategory& base, DescriptorBatch views, std::size_t dims,
                   kernels::Metric metric) {
  auto c = std::make_shared<InstanceCategory>();
  c->id = base.id;
  c->label = base.label;
  c->count = base.count + views.count();
  c->stride = (c->count + COLUMN_PAD - 1) / COLUMN_PAD * COLUMN_PAD;
  c->pair_sum = base.pair_sum;
  c->soa.assign(dims * c->stride, 0.0F);
  for (std::size_t d = 0; d < dims; ++d) {
    std::copy_n(base.soa.begin() + static_cast<std::ptrdiff_t>(d * base.stride), base.count,
                c->soa.begin() + static_cast<std::ptrdiff_t>(d * c->stride));
  }
  std::vector<float> dist(c->count);
  for (std::size_t v = 0; v < views.count(); ++v) {
    const std::span<const float> q = views.view(v);
    const std::size_t col = base.count + v;
    for (std::size_t d = 0; d < dims; ++d) { c->soa[d * c->stride + col] = q[d]; }
    const kernels::DescriptorMatrixView earlier{c->soa, dims, col, c->stride};
    kernels::distances(q, earlier, metric, dist);
    for (std::size_t j = 0; j < col; ++j) { c->pair_sum += static_cast<double>(dist[j]); }
  }
  return c;
}

// ICD of every category (rules in instance_learner.hpp), their mean, and the view total.
std::unique_ptr<InstanceSnapshot> make_snapshot(std::vector<CategoryPtr> categories,
                                                std::uint64_t generation, CategoryId next_id,
                                                const InstanceConfig& cfg) {
  auto s = std::make_unique<InstanceSnapshot>();
  s->categories = std::move(categories);
  s->generation = generation;
  s->next_id = next_id;
  std::vector<PairSum> sums;
  for (const CategoryPtr& c : s->categories) {
    s->views += c->count;
    sums.push_back(PairSum{c->count, c->pair_sum});
  }
  s->mean_icd = category_icds(sums, cfg.min_icd, cfg.default_icd, s->icd);
  return s;
}

// Min (approach I) or mean (approach II) of the distances (L2, or chi-squared for topics) from @p
// query to the views of @p c, walked in chunks of the scratch size (thesis eq. OCD, approaches I
// and II). NaN distances propagate.
float ocd(std::span<const float> query, const InstanceCategory& c, bool mean,
          kernels::Metric metric, std::span<float> buffer) noexcept {
  const std::size_t dims = query.size();
  float min_d = std::numeric_limits<float>::infinity();
  double sum = 0.0;
  bool saw_nan = false;
  for (std::size_t j0 = 0; j0 < c.count; j0 += buffer.size()) {
    const std::size_t n = std::min(buffer.size(), c.count - j0);
    const std::size_t computed =
        std::min(buffer.size(), c.stride - j0);  // padding columns when they fit
    const kernels::DescriptorMatrixView chunk{std::span<const float>(c.soa).subspan(j0), dims,
                                              computed, c.stride};
    kernels::distances(query, chunk, metric, buffer.first(computed));
    for (std::size_t j = 0; j < n; ++j) {
      saw_nan = saw_nan || std::isnan(buffer[j]);
      min_d = std::min(min_d, buffer[j]);
      sum += static_cast<double>(buffer[j]);
    }
  }
  if (saw_nan) { return std::numeric_limits<float>::quiet_NaN(); }
  return mean ? static_cast<float>(sum / static_cast<double>(c.count)) : min_d;
}

// The category without its last views.count() views, which must equal @p views bit for bit;
// null when none would be left. The pair sum is recomputed over the views that stay.
Result<CategoryPtr, LearnError> without_last(const InstanceCategory& c, DescriptorBatch views,
                                             std::size_t dims, kernels::Metric metric) {
  const std::size_t n = views.count();
  if (n > c.count) { return err(LearnError::NOT_LAST_VIEWS); }
  const std::size_t keep = c.count - n;
  for (std::size_t v = 0; v < n; ++v) {
    for (std::size_t d = 0; d < dims; ++d) {
      if (c.soa[d * c.stride + keep + v] != views.view(v)[d]) {
        return err(LearnError::NOT_LAST_VIEWS);
      }
    }
  }
  if (keep == 0) { return CategoryPtr{}; }
  std::vector<float> kept(keep * dims);
  for (std::size_t v = 0; v < keep; ++v) {
    for (std::size_t d = 0; d < dims; ++d) { kept[v * dims + d] = c.soa[d * c.stride + v]; }
  }
  InstanceCategory base;
  base.id = c.id;
  base.label = c.label;
  return extend(base, DescriptorBatch{kept, dims}, dims, metric);
}

}  // namespace

template <>
struct LearnerRules<InstanceLearner> {
  using Category = InstanceCategory;
  using Snapshot = InstanceSnapshot;
  using Views = DescriptorBatch;
  using L = InstanceLearner;

  static Result<Views, LearnError> check(const L& l, DescriptorBatch views) {
    if (auto r = validate_batch(views, l.descriptor_length(), false); !r) return err(r.error());
    return views;
  }
  static CategoryPtr grow(const L& l, const Category* existing, CategoryId id,
                          std::string_view label, Views& views) {
    InstanceCategory fresh;
    fresh.id = id;
    fresh.label = Label::from(label);
    return extend(existing == nullptr ? fresh : *existing, views, l.descriptor_length(),
                  l.config().metric);
  }
  static Result<CategoryPtr, LearnError> shrink(const L& l, const Category& c, Views& views) {
    return without_last(c, views, l.descriptor_length(), l.config().metric);
  }
  static Result<void, LearnError> check_restored(const L& l,
                                                 std::span<const RestoredCategory> categories) {
    if (auto r = validate_restored(categories, l.descriptor_length(), false); !r)
      return err(r.error());
    for (const RestoredCategory& rc : categories)
      if (rc.views.count() == 0) return err(LearnError::NO_VIEWS);  // a model alone is not enough
    return {};
  }
  static Result<CategoryPtr, LearnError> rebuild(const L& l, const RestoredCategory& rc) {
    InstanceCategory base;
    base.id = rc.id;
    base.label = Label::from(rc.label);
    return extend(base, rc.views, l.descriptor_length(), l.config().metric);
  }
  static std::unique_ptr<Snapshot> finish(const L& l, std::vector<CategoryPtr> categories,
                                          std::uint64_t generation, CategoryId next_id) {
    return make_snapshot(std::move(categories), generation, next_id, l.config());
  }
  static std::pair<std::size_t, std::size_t> held(const L& l, const Snapshot& s) {
    return {s.views, s.views * l.descriptor_length()};
  }
  static CategorySummary summary(const L&, const Snapshot& s, std::size_t k) {
    const InstanceCategory& c = *s.categories[k];
    return CategorySummary{c.id, c.label, c.count, s.icd[k]};
  }
};

}  // namespace orthoflow::learning

#include "learning/detail/learner_skeleton.inl"

namespace orthoflow::learning {

template class SkeletonLearner<InstanceLearner>;

InstanceLearner::InstanceLearner(const InstanceConfig& cfg) : cfg_(cfg) {
  OF_ENFORCE(cfg.descriptor_length > 0, "InstanceConfig::descriptor_length must be positive");
  enforce_icd_config(cfg.default_icd, cfg.min_icd, cfg.classification_threshold, "InstanceConfig");
  start();
}

Prediction InstanceLearner::ask(std::span<const float> descriptor,
                                AskScratch& scratch) const noexcept {
  const auto snap = cell().read(scratch.slot_hint);
  RankedScores ranked(false);
  if (descriptor.size() != cfg_.descriptor_length) { return ranked.wrong_length(snap->generation); }
  const bool mean = cfg_.normalise && cfg_.approach == NocdApproach::MEAN_DISTANCE;
  for (std::size_t k = 0; k < snap->categories.size(); ++k) {
    const InstanceCategory& c = *snap->categories[k];
    const float o = ocd(descriptor, c, mean, cfg_.metric, scratch.distances());
    ranked.offer(nocd_score(o, snap->icd[k], snap->mean_icd, cfg_.normalise, mean), c.id, c.label);
  }
  return with_threshold(ranked.prediction(snap->generation), cfg_.classification_threshold);
}

}  // namespace orthoflow::learning
