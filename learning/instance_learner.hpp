#pragma once
/// @file
/// @brief Instance-based open-ended learner (thesis chapter 5, "Normalized Object-Category
/// Distance"): a category is the set of its stored views; D = Euclidean (L2) distance between GOOD
/// descriptors and bags of words, chi-squared between topic histograms (PIPELINE.md section 7;
/// InstanceConfig::metric).
/// - ICD(C) = sum_{U != V} D(U, V) / (|C| (|C| - 1))  (mean pairwise distance)
/// - approach I:  OCD = min_{O in C} D(T, O),  NOCD = OCD / ICD(C)
/// - approach II: OCD = mean_{O in C} D(T, O), NOCD = 2 OCD / (ICD(C) + mean ICD over categories)
/// - label = argmin NOCD, Unknown when min NOCD > CT.  Plain NN (normalise = false): score = min L2
/// over
///   every stored view, Unknown when it exceeds CT.
/// ICD of a category with one view is undefined: it is replaced by the mean ICD of the categories
/// with two or more views, or by InstanceConfig::default_icd when there are none. ICDs below
/// min_icd (duplicate views) are clamped to min_icd so NOCD stays finite.
#include <limits>

#include "kernels/distance.hpp"
#include "learning/learner_skeleton.hpp"

namespace orthoflow::learning {

/// @brief How OCD and NOCD are formed.
enum class NocdApproach : std::uint8_t {
  MIN_DISTANCE = 1,
  MEAN_DISTANCE = 2
};  ///< thesis approach I / II

/// @brief Plain configuration of InstanceLearner (validated by the constructor: OF_ENFORCE).
struct InstanceConfig {
  std::size_t descriptor_length = 675;  ///< 3 n^2 (n = 15)
  NocdApproach approach = NocdApproach::MIN_DISTANCE;
  bool normalise = true;  ///< false: plain nearest neighbour, score = the distance
  kernels::Metric metric = kernels::Metric::L2;  ///< D; learning::make_learner() picks
                                                 ///< CHI_SQUARED for LDA topic histograms
  float classification_threshold =
      std::numeric_limits<float>::infinity();  ///< CT; infinity = never Unknown
  float default_icd =
      0.1F;               ///< ICD used while no category has two views (L2 units of the descriptor)
  float min_icd = 1e-6F;  ///< floor of every ICD
};

/// @brief Instance-based learner, see file comment. Thread-safe as described in
/// learning/learner.hpp.
/// @note ask() is deterministic for one snapshot; SIMD distances (kernels::distances, L2) agree
/// with the scalar kernel within 1e-5 relative.
class InstanceLearner final : public SkeletonLearner<InstanceLearner> {
 public:
  /// @pre cfg.descriptor_length > 0, default_icd > 0, min_icd > 0, CT not NaN (OF_ENFORCE).
  explicit InstanceLearner(const InstanceConfig& cfg);

  [[nodiscard]] Prediction ask(std::span<const float> descriptor,
                               AskScratch& scratch) const noexcept override;
  [[nodiscard]] std::size_t descriptor_length() const noexcept override {
    return cfg_.descriptor_length;
  }
  [[nodiscard]] const char* kind() const noexcept override { return "instance"; }
  [[nodiscard]] const InstanceConfig& config() const noexcept { return cfg_; }

 private:
  InstanceConfig cfg_;
};

extern template class SkeletonLearner<InstanceLearner>;

}  // namespace orthoflow::learning
