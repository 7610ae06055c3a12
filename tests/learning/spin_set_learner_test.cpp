// The thesis's instance-based approaches I and II over sets of spin images
// (learning/spin_set_learner.hpp), computed by hand on tiny sets: images of width 1 (6 values),
// each one "x" = (x, 0, 0, 0, 0, 0), so D(U, V) is a mean of nearest differences of numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <vector>

#include "learning/learner_choice.hpp"
#include "learning/spin_set_learner.hpp"

namespace orthoflow::learning {
namespace {

SpinSetConfig tiny(NocdApproach approach = NocdApproach::MIN_DISTANCE, bool normalise = true) {
  SpinSetConfig cfg;
  cfg.set.features.spin.image_width = 1;  // 2 x 3 = 6 values an image
  cfg.set.max_keypoints = 3;              // descriptors of 1 + 3 x 6 = 19 values
  cfg.approach = approach;
  cfg.normalise = normalise;
  return cfg;
}

std::vector<float> set(std::initializer_list<float> xs) {
  std::vector<float> v(19, 0.0F);
  v[0] = static_cast<float>(xs.size());
  std::size_t i = 0;
  for (const float x : xs) v[1 + 6 * i++] = x;
  return v;
}

// A = {A1 = {0, 1}, A2 = {0, 3}}, B = {B1 = {10}, B2 = {14}}.
// D(A1, A2) = (0 + 1) / 2 = 0.5 and D(A2, A1) = (0 + 2) / 2 = 1: ICD(A) = 1.5 / 2 = 0.75, from both
// directions (one alone would give 0.5 or 1). D(B1, B2) = D(B2, B1) = 4: ICD(B) = 4.
void teach_tiny(Learner& learner) {
  for (const auto& [label, view] : {std::pair{"a", set({0, 1})}, std::pair{"a", set({0, 3})},
                                    std::pair{"b", set({10})}, std::pair{"b", set({14})}}) {
    ASSERT_TRUE(learner.teach(label, DescriptorBatch{view, view.size()}));
  }
}

TEST(SpinSetLearner, IcdIsTheMeanOfDOverOrderedPairs) {
  SpinSetLearner learner(tiny());
  teach_tiny(learner);
  const auto c = learner.categories();
  ASSERT_EQ(c.size(), 2U);
  EXPECT_FLOAT_EQ(c[0].spread, 0.75F);
  EXPECT_FLOAT_EQ(c[1].spread, 4.0F);
  EXPECT_EQ(learner.stats().views, 4U);
}

// T = {6}: D(T, A1) = 5, D(T, A2) = 3; D(T, B1) = 4, D(T, B2) = 8.
// - nearest view: A2 at 3 (B1 is at 4): "a";
// - approach I: A 3 / 0.75 = 4, B 4 / 4 = 1: "b";
// - approach II (mean ICD 2.375): A 2 x 4 / 3.125 = 2.56, B 2 x 6 / 6.375 = 1.882: "b".
TEST(SpinSetLearner, NearestApproachOneAndTwoByHand) {
  const std::vector<float> target = set({6});
  struct Case {
    SpinSetConfig cfg;
    const char* label;
    float score;
    float runner_up_score;
  };
  for (const Case& k :
       {Case{tiny(NocdApproach::MIN_DISTANCE, false), "a", 3.0F, 4.0F},
        Case{tiny(NocdApproach::MIN_DISTANCE), "b", 1.0F, 4.0F},
        Case{tiny(NocdApproach::MEAN_DISTANCE), "b", 12.0F / 6.375F, 8.0F / 3.125F}}) {
    SpinSetLearner learner(k.cfg);
    teach_tiny(learner);
    AskScratch scratch;
    learner.prepare(scratch);
    const Prediction p = learner.ask(target, scratch);
    EXPECT_FALSE(p.unknown);
    EXPECT_EQ(p.label.view(), k.label);
    EXPECT_FLOAT_EQ(p.score, k.score);
    EXPECT_FLOAT_EQ(p.runner_up_score, k.runner_up_score);
  }
}

TEST(SpinSetLearner, DIsAsymmetricTheTargetIsU) {
  // T = {0, 10} against A1 = {0, 1} alone: D(T, A1) = (0 + 9) / 2 = 4.5, where D(A1, T) = 0.5.
  SpinSetLearner learner(tiny(NocdApproach::MIN_DISTANCE, false));
  const std::vector<float> a1 = set({0, 1});
  ASSERT_TRUE(learner.teach("a", DescriptorBatch{a1, a1.size()}));
  AskScratch scratch;
  learner.prepare(scratch);
  EXPECT_FLOAT_EQ(learner.ask(set({0, 10}), scratch).score, 4.5F);
}

TEST(SpinSetLearner, UnknownAboveTheThresholdAndForBadTargets) {
  SpinSetConfig cfg = tiny();
  cfg.classification_threshold = 0.9F;  // the best NOCD of T = {6} is 1
  SpinSetLearner learner(cfg);
  teach_tiny(learner);
  AskScratch scratch;
  learner.prepare(scratch);
  EXPECT_TRUE(learner.ask(set({6}), scratch).unknown);
  EXPECT_FALSE(learner.ask(set({0, 2}), scratch).unknown);  // A: (0 + 1) / 2 / 0.75 = 0.67
  std::vector<float> empty = set({});
  EXPECT_TRUE(learner.ask(empty, scratch).unknown) << "no image: nothing to compare";
  EXPECT_TRUE(learner.ask(std::vector<float>(18, 0.0F), scratch).unknown) << "wrong length";
  std::vector<float> nan = set({std::nanf("")});
  EXPECT_TRUE(learner.ask(nan, scratch).unknown);
  AskScratch small(2);  // not prepared: smaller than a set of 3
  EXPECT_TRUE(learner.ask(set({0, 2}), small).unknown);
  learner.prepare(small);
  EXPECT_FALSE(learner.ask(set({0, 2}), small).unknown);
}

TEST(SpinSetLearner, RefusesWhatIsNotASet) {
  SpinSetLearner learner(tiny());
  std::vector<float> v = set({1, 2});
  for (const float count : {0.0F, 4.0F, 1.5F, -1.0F}) {
    v[0] = count;
    EXPECT_EQ(learner.teach("a", {v, v.size()}).error(), LearnError::NOT_A_SPIN_SET) << count;
  }
  v = set({1, 2});
  v[1 + 2 * 6] = 0.5F;  // a value after the second image
  EXPECT_EQ(learner.teach("a", {v, v.size()}).error(), LearnError::NOT_A_SPIN_SET);
  v = set({1, 2});
  EXPECT_EQ(learner.teach("a", {std::span<const float>(v).first(18), 18}).error(),
            LearnError::WRONG_LENGTH);
  EXPECT_EQ(learner.stats().categories, 0U) << "nothing was taught";
}

TEST(SpinSetLearner, RetractForgetAndRestoreGiveTheSameIcds) {
  SpinSetLearner learner(tiny());
  teach_tiny(learner);
  const std::vector<float> b2 = set({14});
  ASSERT_TRUE(learner.retract("b", {b2, b2.size()}));
  auto c = learner.categories();
  EXPECT_EQ(c[1].views, 1U);
  EXPECT_FLOAT_EQ(c[1].spread, 0.75F) << "one view: the others' mean ICD";
  EXPECT_EQ(learner.retract("b", {b2, b2.size()}).error(), LearnError::NOT_LAST_VIEWS);
  // Restore the four views: the ICDs of a fresh teaching.
  std::vector<float> a, b;
  for (const auto& v : {set({0, 1}), set({0, 3})}) a.insert(a.end(), v.begin(), v.end());
  for (const auto& v : {set({10}), set({14})}) b.insert(b.end(), v.begin(), v.end());
  const RestoredCategory restored[] = {{0, "a", {a, 19}, {}, 0}, {1, "b", {b, 19}, {}, 0}};
  ASSERT_TRUE(learner.restore(restored, 2));
  c = learner.categories();
  EXPECT_FLOAT_EQ(c[0].spread, 0.75F);
  EXPECT_FLOAT_EQ(c[1].spread, 4.0F);
  ASSERT_TRUE(learner.forget("a"));
  EXPECT_EQ(learner.categories().size(), 1U);
}

TEST(SpinSetLearner, MakeLearnerGivesSetsTheSetLearnerWhateverTheKind) {
  kernels::SpinSetParams params;
  params.max_keypoints = 3;
  const kernels::DescriptorSpec spec = kernels::DescriptorSpec::make_spin_set(params);
  ASSERT_TRUE(spec.validate());
  EXPECT_FALSE(spec.histogram());
  EXPECT_EQ(spec.length(), 1U + 3U * 153U);
  for (const LearnerKind kind : {LearnerKind::INSTANCE, LearnerKind::BAYES}) {
    const auto learner = make_learner(spec, kind, InstanceConfig{}, BayesConfig{});
    EXPECT_STREQ(learner->kind(), "instance-spin-set");
    EXPECT_EQ(learner->descriptor_length(), spec.length());
  }
}

}  // namespace
}  // namespace orthoflow::learning
