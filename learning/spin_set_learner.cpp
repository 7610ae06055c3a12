#include "learning/spin_set_learner.hpp"

#include <algorithm>
#include <cmath>

#include "kernels/set_distance.hpp"
#include "learning/detail/learner_common.hpp"

namespace orthoflow::learning {

/// One stored view: its images row after row (as D(U, .) reads a U) and as a structure-of-arrays
/// matrix (as D(., V) reads a V), and the descriptor it came from (retract compares it).
struct SetView {
  std::size_t count = 0;
  std::size_t stride = 0;  // count rounded up to COLUMN_PAD: zero columns keep D in its SIMD body
  std::vector<float> rows;
  std::vector<float> soa;  // image_values x stride
  [[nodiscard]] kernels::DescriptorMatrixView matrix(std::size_t dims) const noexcept {
    return {soa, dims, count, stride};
  }
};
using SetViewPtr = std::shared_ptr<const SetView>;

/// One category: its views (shared between snapshots) and the sum of D over its ordered pairs of
/// distinct views, kept so that a teach adds only the new views' pairs.
struct SetCategory {
  CategoryId id = NO_CATEGORY;
  Label label;
  std::vector<SetViewPtr> views;
  double ordered_sum = 0.0;
};

struct SetSnapshot {
  std::vector<std::shared_ptr<const SetCategory>> categories;  // by id
  std::vector<float> icd;                                      // parallel to categories
  float mean_icd = 0.0F;
  std::size_t views = 0;
  std::size_t stored_floats = 0;
  std::uint64_t generation = 0;
  CategoryId next_id = 0;
};

namespace {

using CategoryPtr = std::shared_ptr<const SetCategory>;

// kernels::distances runs SIMD across a set's columns (16 lanes with AVX-512) and finishes with a
// scalar tail; a set of 40 images would spend most of its time there (bench/RESULTS.md "ask per
// representation"). Its columns are padded to a multiple of 16 with zeros, which D never compares.
constexpr std::size_t COLUMN_PAD = 16;
constexpr std::size_t padded(std::size_t n) noexcept {
  return (n + COLUMN_PAD - 1) / COLUMN_PAD * COLUMN_PAD;
}

// The view of a descriptor that spin_set_count() accepted.
SetViewPtr make_view(std::span<const float> descriptor, std::size_t count, std::size_t dims) {
  auto v = std::make_shared<SetView>();
  v->count = count;
  v->rows.assign(descriptor.begin() + 1,
                 descriptor.begin() + 1 + static_cast<std::ptrdiff_t>(count * dims));
  v->stride = padded(count);
  v->soa.assign(v->stride * dims, 0.0F);
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t d = 0; d < dims; ++d) v->soa[d * v->stride + i] = v->rows[i * dims + d];
  return v;
}

// Every view of @p views as a set, or NOT_A_SPIN_SET (validate_batch() ran before).
Result<std::vector<SetViewPtr>, LearnError> sets_of(DescriptorBatch views, std::size_t dims) {
  std::vector<SetViewPtr> out;
  for (std::size_t v = 0; v < views.count(); ++v) {
    const auto count = kernels::spin_set_count(views.view(v), dims);
    if (!count) return err(LearnError::NOT_A_SPIN_SET);
    out.push_back(make_view(views.view(v), *count, dims));
  }
  return out;
}

// D(U, V) with a scratch of V's size.
double set_d(const SetView& u, const SetView& v, std::size_t dims, std::vector<float>& scratch) {
  if (scratch.size() < v.stride) scratch.resize(v.stride);
  return static_cast<double>(kernels::set_distance(u.rows, v.matrix(dims), scratch));
}

// A new category: @p base's views, then @p added, each adding D both ways to every earlier view.
CategoryPtr extend(const SetCategory& base, std::span<const SetViewPtr> added, std::size_t dims) {
  auto c = std::make_shared<SetCategory>(base);
  std::vector<float> scratch;
  for (const SetViewPtr& v : added) {
    for (const SetViewPtr& u : c->views)
      c->ordered_sum += set_d(*v, *u, dims, scratch) + set_d(*u, *v, dims, scratch);
    c->views.push_back(v);
  }
  return c;
}

std::unique_ptr<SetSnapshot> make_snapshot(std::vector<CategoryPtr> categories,
                                           std::uint64_t generation, CategoryId next_id,
                                           const SpinSetConfig& cfg) {
  auto s = std::make_unique<SetSnapshot>();
  s->categories = std::move(categories);
  s->generation = generation;
  s->next_id = next_id;
  std::vector<PairSum> sums;
  for (const CategoryPtr& c : s->categories) {
    s->views += c->views.size();
    for (const SetViewPtr& v : c->views) s->stored_floats += v->rows.size() + v->soa.size();
    // category_icds() divides a sum over unordered pairs by n (n - 1) / 2: half the ordered sum.
    sums.push_back(PairSum{c->views.size(), 0.5 * c->ordered_sum});
  }
  s->mean_icd = category_icds(sums, cfg.min_icd, cfg.default_icd, s->icd);
  return s;
}

}  // namespace

template <>
struct LearnerRules<SpinSetLearner> {
  using Category = SetCategory;
  using Snapshot = SetSnapshot;
  using Views = std::vector<SetViewPtr>;
  using L = SpinSetLearner;

  static Result<Views, LearnError> check(const L& l, DescriptorBatch views) {
    if (auto r = validate_batch(views, l.descriptor_length(), false); !r) return err(r.error());
    return sets_of(views, l.config().set.image_values());
  }
  static CategoryPtr grow(const L& l, const Category* existing, CategoryId id,
                          std::string_view label, Views& sets) {
    SetCategory fresh;
    fresh.id = id;
    fresh.label = Label::from(label);
    return extend(existing == nullptr ? fresh : *existing, sets, l.config().set.image_values());
  }
  static Result<CategoryPtr, LearnError> shrink(const L& l, const Category& c, Views& sets) {
    const std::size_t n = sets.size();
    if (n > c.views.size()) return err(LearnError::NOT_LAST_VIEWS);
    const std::size_t keep = c.views.size() - n;
    for (std::size_t v = 0; v < n; ++v)
      if (c.views[keep + v]->rows != sets[v]->rows) return err(LearnError::NOT_LAST_VIEWS);
    if (keep == 0) return CategoryPtr{};
    SetCategory base;
    base.id = c.id;
    base.label = c.label;
    return extend(base, std::span<const SetViewPtr>(c.views).first(keep),
                  l.config().set.image_values());
  }
  static Result<void, LearnError> check_restored(const L& l,
                                                 std::span<const RestoredCategory> categories) {
    if (auto r = validate_restored(categories, l.descriptor_length(), false); !r)
      return err(r.error());
    for (const RestoredCategory& rc : categories)
      if (rc.views.count() == 0) return err(LearnError::NO_VIEWS);
    return {};
  }
  static Result<CategoryPtr, LearnError> rebuild(const L& l, const RestoredCategory& rc) {
    auto sets = sets_of(rc.views, l.config().set.image_values());
    if (!sets) return err(sets.error());
    SetCategory base;
    base.id = rc.id;
    base.label = Label::from(rc.label);
    return extend(base, *sets, l.config().set.image_values());
  }
  static std::unique_ptr<Snapshot> finish(const L& l, std::vector<CategoryPtr> categories,
                                          std::uint64_t generation, CategoryId next_id) {
    return make_snapshot(std::move(categories), generation, next_id, l.config());
  }
  static std::pair<std::size_t, std::size_t> held(const L&, const Snapshot& s) {
    return {s.views, s.stored_floats};
  }
  static CategorySummary summary(const L&, const Snapshot& s, std::size_t k) {
    const SetCategory& c = *s.categories[k];
    return CategorySummary{c.id, c.label, c.views.size(), s.icd[k]};
  }
};

}  // namespace orthoflow::learning

#include "learning/detail/learner_skeleton.inl"

namespace orthoflow::learning {

template class SkeletonLearner<SpinSetLearner>;

SpinSetLearner::SpinSetLearner(const SpinSetConfig& cfg) : cfg_(cfg) {
  OF_ENFORCE(cfg.set.valid(), "SpinSetConfig::set is not a valid spin-image set");
  enforce_icd_config(cfg.default_icd, cfg.min_icd, cfg.classification_threshold, "SpinSetConfig");
  start();
}

void SpinSetLearner::prepare(AskScratch& scratch) const {
  scratch.reserve_distances(padded(cfg_.set.max_keypoints));
}

Prediction SpinSetLearner::ask(std::span<const float> descriptor,
                               AskScratch& scratch) const noexcept {
  const auto snap = cell().read(scratch.slot_hint);
  RankedScores ranked(false);
  const std::size_t dims = cfg_.set.image_values();
  const auto count = descriptor.size() == cfg_.set.length()
                         ? kernels::spin_set_count(descriptor, dims)
                         : std::nullopt;
  const std::span<float> buffer = scratch.distances();
  if (!count || buffer.size() < cfg_.set.max_keypoints)
    return RankedScores::wrong_length(snap->generation);
  const std::span<const float> target = descriptor.subspan(1, *count * dims);
  const bool mean = cfg_.normalise && cfg_.approach == NocdApproach::MEAN_DISTANCE;
  for (std::size_t k = 0; k < snap->categories.size(); ++k) {
    const SetCategory& c = *snap->categories[k];
    float min_d = std::numeric_limits<float>::infinity();
    double sum = 0.0;
    for (const SetViewPtr& v : c.views) {
      const float d = kernels::set_distance(target, v->matrix(dims), buffer);
      min_d = std::isnan(d) ? d : std::min(min_d, d);  // NaN is never a smaller distance
      sum += static_cast<double>(d);
    }
    const float o = mean ? static_cast<float>(sum / static_cast<double>(c.views.size())) : min_d;
    ranked.offer(nocd_score(o, snap->icd[k], snap->mean_icd, cfg_.normalise, mean), c.id, c.label);
  }
  return with_threshold(ranked.prediction(snap->generation), cfg_.classification_threshold);
}

}  // namespace orthoflow::learning
