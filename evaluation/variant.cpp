#include "evaluation/variant.hpp"

#include "core/assert.hpp"
#include "learning/learner_choice.hpp"

namespace orthoflow::evaluation {

std::string Variant::name() const {
  std::string n = learner == LearnerKind::BAYES ? "bayes" : "instance";
  if (learner == LearnerKind::BAYES && topic_histogram_bayes &&
      representation == kernels::DescriptorKind::LOCAL_LDA)
    n += "-topics";
  if (learner == LearnerKind::INSTANCE) {
    n += rule == InstanceRule::NEAREST      ? "-nn"
         : rule == InstanceRule::APPROACH_1 ? "-nocd1"
                                            : "-nocd2";
  }
  if (representation == kernels::DescriptorKind::BOW) {
    return n + "/bow/" + std::to_string(dictionary ? dictionary->words : 0);
  }
  if (representation == kernels::DescriptorKind::LDA) {
    return n + "/lda/" +
           std::to_string(dictionary && dictionary->topics ? dictionary->topics->topics : 0);
  }
  if (representation == kernels::DescriptorKind::LOCAL_LDA) {
    return n + "/local-lda/" + std::to_string(local_topics.topics) + "x" +
           std::to_string(dictionary ? dictionary->words : 0);
  }
  if (representation == kernels::DescriptorKind::SPIN_SET) {
    return n + "/spin/" + std::to_string(spin_set.max_keypoints) + "x" +
           std::to_string(spin_set.image_values());
  }
  n += mode == kernels::GoodMode::INVARIANT ? "/invariant/" : "/reference/";
  return n + std::to_string(bins);
}

kernels::DescriptorSpec Variant::spec() const {
  if (representation == kernels::DescriptorKind::BOW) {
    return kernels::DescriptorSpec::make_bow(dictionary);
  }
  if (representation == kernels::DescriptorKind::LDA) {
    return kernels::DescriptorSpec::make_lda(dictionary);
  }
  if (representation == kernels::DescriptorKind::LOCAL_LDA) {
    return kernels::DescriptorSpec::make_local_lda(dictionary, local_topics);
  }
  if (representation == kernels::DescriptorKind::SPIN_SET) {
    return kernels::DescriptorSpec::make_spin_set(spin_set);
  }
  return kernels::DescriptorSpec::make_good(bins, mode);
}

ViewDescription Variant::descriptor(Perturbation p, double amount_m, std::uint64_t seed) const {
  return ViewDescription{spec(), p, amount_m, seed};
}

std::unique_ptr<learning::Learner> Variant::make_learner() const {
  learning::InstanceConfig cfg;
  cfg.normalise = rule != InstanceRule::NEAREST;
  cfg.approach = rule == InstanceRule::APPROACH_2 ? learning::NocdApproach::MEAN_DISTANCE
                                                  : learning::NocdApproach::MIN_DISTANCE;
  return learning::make_learner(spec(),
                                learner == LearnerKind::BAYES ? learning::LearnerKind::BAYES
                                                              : learning::LearnerKind::INSTANCE,
                                cfg, learning::BayesConfig{}, topic_histogram_bayes);
}

ClassLearner::ClassLearner(const Variant& variant, const std::vector<std::string>& categories)
    : categories_(categories), learner_(variant.make_learner()) {
  learner_->prepare(scratch_);
}

void ClassLearner::teach(std::uint32_t cls, std::span<const float> views) {
  const std::size_t length = learner_->descriptor_length();
  auto id = learner_->teach(categories_[cls], learning::DescriptorBatch{views, length});
  // The dataset scan validated labels and describe_dataset() produced finite histograms of this
  // length.
  OF_ENFORCE(id.has_value(), "evaluation: teach refused a dataset view");
  class_of_[*id] = cls;
}

std::optional<std::uint32_t> ClassLearner::ask(std::span<const float> view) {
  const learning::Prediction p = learner_->ask(view, scratch_);
  if (p.unknown) { return std::nullopt; }
  const auto it = class_of_.find(p.category);
  if (it == class_of_.end()) { return std::nullopt; }
  return it->second;
}

}  // namespace orthoflow::evaluation
