#include "learning/learner_choice.hpp"

#include "learning/local_lda_learner.hpp"
#include "learning/spin_set_learner.hpp"

namespace orthoflow::learning {

const char* to_string(LearnerKind kind) noexcept {
  return kind == LearnerKind::BAYES ? "bayes" : "instance";
}

std::unique_ptr<Learner> make_learner(const kernels::DescriptorSpec& spec, LearnerKind kind,
                                      InstanceConfig instance, BayesConfig bayes,
                                      bool topic_histogram_bayes) {
  const std::size_t length = spec.length();
  if (spec.kind == kernels::DescriptorKind::LOCAL_LDA) {
    LocalLdaConfig cfg;
    cfg.words = length;
    cfg.topics = spec.local_topics;
    if (kind == LearnerKind::BAYES) {
      cfg.decision =
          topic_histogram_bayes ? LocalLdaDecision::TOPIC_HISTOGRAM : LocalLdaDecision::LIKELIHOOD;
    } else {
      cfg.decision = !instance.normalise                               ? LocalLdaDecision::NEAREST
                     : instance.approach == NocdApproach::MIN_DISTANCE ? LocalLdaDecision::NOCD_1
                                                                       : LocalLdaDecision::NOCD_2;
    }
    cfg.classification_threshold = instance.classification_threshold;
    cfg.default_icd = instance.default_icd;
    cfg.min_icd = instance.min_icd;
    cfg.count_scale = bayes.count_scale;
    return std::make_unique<LocalLdaLearner>(cfg);
  }
  if (spec.kind == kernels::DescriptorKind::SPIN_SET) {  // instance-based whatever @p kind says
    SpinSetConfig cfg;
    cfg.set = spec.spin_set;
    cfg.approach = instance.approach;
    cfg.normalise = instance.normalise;
    cfg.classification_threshold = instance.classification_threshold;
    cfg.default_icd = instance.default_icd;
    cfg.min_icd = instance.min_icd;
    return std::make_unique<SpinSetLearner>(cfg);
  }
  if (kind == LearnerKind::BAYES) {
    bayes.descriptor_length = length;
    return std::make_unique<BayesLearner>(bayes);
  }
  instance.descriptor_length = length;
  // PIPELINE.md section 7: topic histograms are compared by chi-squared.
  if (spec.kind == kernels::DescriptorKind::LDA) instance.metric = kernels::Metric::CHI_SQUARED;
  return std::make_unique<InstanceLearner>(instance);
}

}  // namespace orthoflow::learning
