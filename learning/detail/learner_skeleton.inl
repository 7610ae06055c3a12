#pragma once
/// @file
/// @brief SkeletonLearner<L>'s flows (learning/learner_skeleton.hpp), instantiated once in L's .cpp
/// after its LearnerRules<L>. Internal to learning/. What LearnerRules<L> holds:
/// - `Category` (with `id` and `label`) and `Snapshot` (with `categories`, a vector of
///   shared_ptr<const Category> by id, and `generation`, `next_id`), and `Views`: a taught batch
///   in the learner's own checked form;
/// - `check(l, views)` -> Result<Views, LearnError>: the batch rules (validate_batch and the
///   learner's own), before any lock is taken;
/// - `grow(l, existing_or_null, id, label, views)` -> shared_ptr<const Category>: the category
///   with the views added (thesis: C_n = C_{n-1} U {O_n});
/// - `shrink(l, category, views)` -> Result<shared_ptr<const Category>, LearnError>: the category
///   without its last views, which must be @p views (NOT_LAST_VIEWS), null when none is left;
/// - `check_restored(l, categories)` -> Result<void, LearnError> and `rebuild(l, restored)` ->
///   Result<shared_ptr<const Category>, LearnError>: the start-up load;
/// - `finish(l, categories, generation, next_id)` -> unique_ptr<Snapshot>: what every snapshot
///   derives from its categories (ICDs, totals);
/// - `held(l, snapshot)` -> std::pair{views, stored floats}, and `summary(l, snapshot, k)` ->
///   CategorySummary of category k.
#include <algorithm>
#include <utility>

#include "learning/detail/category_writer.hpp"
#include "learning/detail/learner_common.hpp"
#include "learning/learner_skeleton.hpp"
#include "learning/snapshot_cell.hpp"

namespace orthoflow::learning {

template <class L>
struct LearnerCell : SnapshotCell<typename LearnerRules<L>::Snapshot> {
  using SnapshotCell<typename LearnerRules<L>::Snapshot>::SnapshotCell;
};

template <class L>
SkeletonLearner<L>::~SkeletonLearner() = default;

template <class L>
auto SkeletonLearner<L>::finisher() const {
  return [this](auto categories, std::uint64_t generation, CategoryId next_id) {
    return LearnerRules<L>::finish(self(), std::move(categories), generation, next_id);
  };
}

template <class L>
void SkeletonLearner<L>::start() {
  cell_ = std::make_unique<LearnerCell<L>>(LearnerRules<L>::finish(self(), {}, 0, 0));
}

template <class L>
Result<CategoryId, LearnError> SkeletonLearner<L>::teach(std::string_view label,
                                                         DescriptorBatch views) {
  using Rules = LearnerRules<L>;
  if (auto r = validate_label(label); !r) return err(r.error());
  auto checked = Rules::check(self(), views);
  if (!checked) return err(checked.error());
  auto make = [&](const typename Rules::Category* existing, CategoryId id) {
    return Rules::grow(self(), existing, id, label, *checked);
  };
  return upsert_category(writer_, *cell_, label, make, finisher());
}

template <class L>
Result<void, LearnError> SkeletonLearner<L>::forget(std::string_view label) {
  return erase_category(writer_, *cell_, label, finisher());
}

template <class L>
Result<void, LearnError> SkeletonLearner<L>::retract(std::string_view label,
                                                     DescriptorBatch views) {
  using Rules = LearnerRules<L>;
  auto checked = Rules::check(self(), views);
  if (!checked) return err(checked.error());
  auto make = [&](const typename Rules::Category& c) { return Rules::shrink(self(), c, *checked); };
  return shrink_category(writer_, *cell_, label, make, finisher());
}

template <class L>
Result<void, LearnError> SkeletonLearner<L>::restore(std::span<const RestoredCategory> categories,
                                                     CategoryId next_id) {
  using Rules = LearnerRules<L>;
  if (auto r = Rules::check_restored(self(), categories); !r) return err(r.error());
  std::vector<std::shared_ptr<const typename Rules::Category>> next;
  for (const RestoredCategory& rc : categories) {
    auto c = Rules::rebuild(self(), rc);
    if (!c) return err(c.error());
    next.push_back(std::move(*c));
    next_id = std::max(next_id, rc.id + 1);
  }
  replace_categories(writer_, *cell_, std::move(next), next_id, finisher());
  return {};
}

template <class L>
LearnerStats SkeletonLearner<L>::stats() const noexcept {
  std::size_t hint = 0;
  const auto snap = cell_->read(hint);
  const auto [views, stored] = LearnerRules<L>::held(self(), *snap);
  return LearnerStats{snap->categories.size(), views, stored, snap->generation,
                      cell_->retired_pending()};
}

template <class L>
std::vector<CategorySummary> SkeletonLearner<L>::categories() const {
  std::size_t hint = 0;
  const auto snap = cell_->read(hint);
  std::vector<CategorySummary> out;
  for (std::size_t k = 0; k < snap->categories.size(); ++k)
    out.push_back(LearnerRules<L>::summary(self(), *snap, k));
  return out;
}

}  // namespace orthoflow::learning
