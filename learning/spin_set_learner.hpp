#pragma once
/// @file
/// @brief The thesis's instance-based approaches I and II on their own objects (chapter 5): a view
/// is the set of its spin images (kernels/spin_set.hpp), a category the set of its views, and two
/// views are compared by the asymmetric set distance
///   D(U, V) = (1 / |U|) sum over u in U of min over v in V of ||u - v|| (kernels/set_distance.hpp)
/// - OCD(T, C): min over the views O of C of D(T, O) (approach I), or their mean (approach II);
/// - ICD(C): the mean of D over the ordered pairs of distinct views of C, sum_{U != V} D(U, V) /
///   (|C| (|C| - 1)) (both directions, as D is not symmetric);
/// - NOCD and Unknown as InstanceLearner (instance_learner.hpp): approach I OCD / ICD(C), approach
///   II 2 OCD / (ICD(C) + mean ICD), Unknown when the best NOCD exceeds CT; plain nearest view when
///   normalise is off. A category of one view takes the others' mean ICD (or default_icd).
/// Naive Bayes has no form over sets: learning::make_learner() gives every SPIN_SET specification
/// this learner. Thread-safety and snapshots as every Learner (learner.hpp).
#include "kernels/spin_set.hpp"
#include "learning/instance_learner.hpp"
#include "learning/learner_skeleton.hpp"

namespace orthoflow::learning {

struct SpinSetConfig {
  kernels::SpinSetParams set{};  ///< the descriptors' layout: image values and capacity
  NocdApproach approach = NocdApproach::MIN_DISTANCE;
  bool normalise = true;  ///< false: plain nearest view, score = min D(T, O)
  float classification_threshold = std::numeric_limits<float>::infinity();  ///< CT
  float default_icd = 0.1F;  ///< ICD while no category has two views
  float min_icd = 1e-6F;     ///< floor of every ICD
};

/// @brief See the file comment. Teaching a view computes D both ways to every view of its
/// category (O(views x images^2) distances); asking computes D(T, O) for every stored view.
/// @note ask() allocates nothing once prepare() has sized the scratch's distances (one per image
/// of a stored set); an unprepared scratch too small for a set gets an Unknown answer, score NaN.
class SpinSetLearner final : public SkeletonLearner<SpinSetLearner> {
 public:
  /// @pre cfg.set.valid(), default_icd > 0, min_icd > 0, CT not NaN (OF_ENFORCE).
  explicit SpinSetLearner(const SpinSetConfig& cfg);

  [[nodiscard]] Prediction ask(std::span<const float> descriptor,
                               AskScratch& scratch) const noexcept override;
  void prepare(AskScratch& scratch) const override;
  [[nodiscard]] std::size_t descriptor_length() const noexcept override {
    return cfg_.set.length();
  }
  [[nodiscard]] const char* kind() const noexcept override { return "instance-spin-set"; }
  [[nodiscard]] const SpinSetConfig& config() const noexcept { return cfg_; }

 private:
  SpinSetConfig cfg_;
};

extern template class SkeletonLearner<SpinSetLearner>;

}  // namespace orthoflow::learning
