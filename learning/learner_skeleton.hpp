#pragma once
/// @file
/// @brief SkeletonLearner<L>: the one skeleton every open-ended learner fills in. It owns what all
/// learners share: the copy-on-write snapshot of immutable categories read by ask() without a lock
/// (learning/snapshot_cell.hpp), the writer lock, and the flows of teach, retract, forget, restore,
/// stats and categories (learning/detail/learner_skeleton.inl). A learner L keeps in its own files
/// only what differs: its category and snapshot types and the rules that grow, shrink, rebuild and
/// summarise them (a specialisation of LearnerRules<L> in its .cpp), and ask().
///
/// How a learner fills it in (instance_learner.cpp is the shortest example):
/// 1. `class L final : public SkeletonLearner<L>` with ask(), descriptor_length(), kind() and a
///    public config(); the constructor checks the configuration and then calls start().
/// 2. In L's .cpp: `template <> struct LearnerRules<L> { ... }` (members listed in the .inl),
///    then `#include "learning/detail/learner_skeleton.inl"` and
///    `template class SkeletonLearner<L>;`. L's header declares `extern template class
///    SkeletonLearner<L>;` so no other file instantiates it.
/// Thread-safety and determinism are Learner's (learning/learner.hpp).
#include <cstddef>
#include <memory>
#include <mutex>
#include <span>
#include <string_view>
#include <vector>

#include "learning/learner.hpp"

namespace orthoflow::learning {

/// @brief What learner @p L fills in; specialised in L's .cpp (see the file comment).
template <class L>
struct LearnerRules;
/// @brief The snapshot cell holding L's snapshots (defined in
/// learning/detail/learner_skeleton.inl).
template <class L>
struct LearnerCell;

/// @brief The shared half of a learner; see the file comment. @note Thread-safe as Learner.
template <class L>
class SkeletonLearner : public Learner {
 public:
  ~SkeletonLearner() override;

  [[nodiscard]] Result<CategoryId, LearnError> teach(std::string_view label,
                                                     DescriptorBatch views) final;
  [[nodiscard]] Result<void, LearnError> forget(std::string_view label) final;
  [[nodiscard]] Result<void, LearnError> retract(std::string_view label,
                                                 DescriptorBatch views) final;
  [[nodiscard]] Result<void, LearnError> restore(std::span<const RestoredCategory> categories,
                                                 CategoryId next_id) final;
  [[nodiscard]] LearnerStats stats() const noexcept final;
  [[nodiscard]] std::vector<CategorySummary> categories() const final;

 protected:
  SkeletonLearner() = default;
  /// @brief Publishes the first, empty snapshot. @pre Called once, by L's constructor, after L's
  /// configuration is checked (the rules read it).
  void start();
  /// @brief The snapshots, for ask() and L's own readers. @pre start() was called.
  [[nodiscard]] const LearnerCell<L>& cell() const noexcept { return *cell_; }

 private:
  [[nodiscard]] const L& self() const noexcept { return static_cast<const L&>(*this); }
  [[nodiscard]] auto finisher() const;

  std::mutex writer_;
  std::unique_ptr<LearnerCell<L>> cell_;
};

}  // namespace orthoflow::learning
