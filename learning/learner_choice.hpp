#pragma once
/// @file
/// @brief Which learner a representation is learned with: one factory for the memory, the learning
/// service and the evaluation, so a specification always gets the same learner.
#include <memory>

#include "kernels/descriptor_spec.hpp"
#include "learning/bayes_learner.hpp"
#include "learning/instance_learner.hpp"

namespace orthoflow::learning {

/// @brief Which learner a memory feeds. Every store can be opened with either (views and Bayes
/// accumulators are always both stored).
enum class LearnerKind : std::uint8_t { INSTANCE, BAYES };
/// @brief "instance" or "bayes".
[[nodiscard]] const char* to_string(LearnerKind kind) noexcept;

/// @brief A fresh learner for descriptors of @p spec: for LOCAL_LDA word counts a LocalLdaLearner
/// (BAYES: the topic models' likelihood, or naive Bayes over topic histograms when @p
/// topic_histogram_bayes; INSTANCE: @p instance's rule, plain nearest, NOCD approach I or II, its
/// CT and ICDs); for SPIN_SET sets a SpinSetLearner with @p instance's rule, CT and ICDs (naive
/// Bayes has no form over sets: @p kind is not used); otherwise an InstanceLearner (chi-squared for
/// LDA topic histograms, PIPELINE.md section 7; L2 otherwise) or a BayesLearner. The
/// configurations' descriptor_length is set from the specification. @pre spec.validate() succeeded.
[[nodiscard]] std::unique_ptr<Learner> make_learner(const kernels::DescriptorSpec& spec,
                                                    LearnerKind kind, InstanceConfig instance,
                                                    BayesConfig bayes,
                                                    bool topic_histogram_bayes = false);

}  // namespace orthoflow::learning
