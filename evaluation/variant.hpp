#pragma once
/// @file
/// @brief One approach under comparison: a learner (instance-based with its recognition rule, or
/// naive Bayes) on GOOD descriptors of one mode and bin count. Every variant of an evaluation sees
/// the same category orders, folds and view orders (they depend on the seed and the run only).
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>

#include "evaluation/descriptors.hpp"
#include "learning/learner.hpp"

namespace orthoflow::evaluation {

enum class LearnerKind : std::uint8_t { INSTANCE, BAYES };
/// @brief Recognition rule of the instance-based learner: plain nearest neighbour (L2), or the
/// thesis's normalised distances, approach I (min) and approach II (mean), with no Unknown
/// threshold.
enum class InstanceRule : std::uint8_t { NEAREST, APPROACH_1, APPROACH_2 };

struct Variant {
  LearnerKind learner = LearnerKind::INSTANCE;
  InstanceRule rule = InstanceRule::NEAREST;
  kernels::GoodMode mode = kernels::GoodMode::INVARIANT;
  std::size_t bins = 15;
  /// The representation: GOOD (mode, bins), BOW (this dictionary's words) or LDA (its topics).
  kernels::DescriptorKind representation = kernels::DescriptorKind::GOOD;
  std::shared_ptr<const kernels::VisualDictionary> dictionary;
  /// LOCAL_LDA: the topics every category learns.
  kernels::LocalTopics local_topics{};
  /// LOCAL_LDA with the Bayes learner: naive Bayes over topic histograms instead of the topic
  /// models' likelihood (learning/local_lda_learner.hpp).
  bool topic_histogram_bayes = false;
  /// SPIN_SET: the spin images' parameters and the most a view keeps (the instance learner only).
  kernels::SpinSetParams spin_set{};
  /// @brief The descriptor specification of this variant.
  [[nodiscard]] kernels::DescriptorSpec spec() const;
  /// @brief "instance-nn/invariant/15", "bayes/reference/5", "instance-nn/bow/70", "bayes/lda/30",
  /// "bayes/local-lda/30x90", "instance-nocd1/spin/128x153" (images x values),
  /// ...
  [[nodiscard]] std::string name() const;
  /// @brief The descriptor parameters of this variant with perturbation @p p of @p amount_m.
  [[nodiscard]] ViewDescription descriptor(Perturbation p = Perturbation::NONE,
                                           double amount_m = 0.0, std::uint64_t seed = 0) const;
  /// @brief A fresh, empty learner.
  [[nodiscard]] std::unique_ptr<learning::Learner> make_learner() const;
};

/// @brief Teaches and asks a learner in dataset class indices (labels = category names).
class ClassLearner {
 public:
  ClassLearner(const Variant& variant, const std::vector<std::string>& categories);
  /// @brief Teaches @p views (row-major, one row per view) as class @p cls.
  void teach(std::uint32_t cls, std::span<const float> views);
  /// @brief The predicted class, or empty for Unknown.
  [[nodiscard]] std::optional<std::uint32_t> ask(std::span<const float> view);
  [[nodiscard]] const learning::Learner& learner() const noexcept { return *learner_; }

 private:
  const std::vector<std::string>& categories_;
  std::unique_ptr<learning::Learner> learner_;
  learning::AskScratch scratch_;
  std::unordered_map<learning::CategoryId, std::uint32_t> class_of_;
};

}  // namespace orthoflow::evaluation
