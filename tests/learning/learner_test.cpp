// Instance-based and naive Bayes learners against hand-computed examples (thesis chapter 5,
// PIPELINE.md section 7), open-endedness, forget, restore, and every LearnError.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "learning/bayes_learner.hpp"
#include "learning/instance_learner.hpp"

namespace orthoflow::learning {
namespace {

DescriptorBatch batch(const std::vector<float>& values, std::size_t length) {
  return {values, length};
}

// A = {(0,0), (2,0)}: ICD 2.  B = {(10,0), (10,4)}: ICD 4.  Query T = (5,0).
// D(T, A) = {5, 3}; D(T, B) = {5, sqrt(41)}.
std::unique_ptr<InstanceLearner> make_ab(const InstanceConfig& base) {
  InstanceConfig cfg = base;
  cfg.descriptor_length = 2;
  auto learner = std::make_unique<InstanceLearner>(cfg);
  const std::vector<float> a{0, 0, 2, 0};
  const std::vector<float> b{10, 0, 10, 4};
  EXPECT_EQ(*learner->teach("A", batch(a, 2)), 0U);
  EXPECT_EQ(*learner->teach("B", batch(b, 2)), 1U);
  return learner;
}
const std::vector<float> QUERY{5, 0};

// Topic histograms are compared by chi-squared (PIPELINE.md section 7): A = (0.5, 0.5), B = (1, 0),
// T = (0.8, 0.2). L2: D(T, A) = 0.424 > D(T, B) = 0.283, so B. Chi-squared, sum (a - b)^2 / (a +
// b): D(T, A) = 0.09 / 1.3 + 0.09 / 0.7 = 0.1978 < D(T, B) = 0.04 / 1.8 + 0.04 / 0.2 = 0.2222, so
// A.
TEST(InstanceLearner, TheMetricIsChosenAndChiSquaredIsComputedAsByHand) {
  for (const kernels::Metric metric : {kernels::Metric::L2, kernels::Metric::CHI_SQUARED}) {
    InstanceConfig cfg;
    cfg.descriptor_length = 2;
    cfg.normalise = false;
    cfg.metric = metric;
    InstanceLearner learner(cfg);
    ASSERT_TRUE(learner.teach("A", batch({0.5F, 0.5F}, 2)));
    ASSERT_TRUE(learner.teach("B", batch({1.0F, 0.0F}, 2)));
    AskScratch scratch;
    const Prediction p = learner.ask(std::vector<float>{0.8F, 0.2F}, scratch);
    if (metric == kernels::Metric::L2) {
      EXPECT_EQ(p.label.view(), "B");
      EXPECT_NEAR(p.score, std::sqrt(0.08F), 1e-6F);
    } else {
      EXPECT_EQ(p.label.view(), "A");
      EXPECT_NEAR(p.score, 0.09F / 1.3F + 0.09F / 0.7F, 1e-6F);
      EXPECT_NEAR(p.runner_up_score, 0.04F / 1.8F + 0.04F / 0.2F, 1e-6F);
    }
  }
}

TEST(InstanceLearner, ApproachOneNormalisesMinDistanceByIcd) {
  auto learner_ptr = make_ab(InstanceConfig{});
  auto& learner = *learner_ptr;
  AskScratch scratch;
  const Prediction p = learner.ask(QUERY, scratch);
  // NOCD_A = 3 / 2 = 1.5, NOCD_B = 5 / 4 = 1.25: the wider category wins although A is nearer.
  EXPECT_FALSE(p.unknown);
  EXPECT_EQ(p.label.view(), "B");
  EXPECT_EQ(p.category, 1U);
  EXPECT_NEAR(p.score, 1.25F, 1e-5F);
  EXPECT_EQ(p.runner_up.view(), "A");
  EXPECT_NEAR(p.runner_up_score, 1.5F, 1e-5F);
  const auto cats = learner.categories();
  ASSERT_EQ(cats.size(), 2U);
  EXPECT_NEAR(cats[0].spread, 2.0F, 1e-6F);
  EXPECT_NEAR(cats[1].spread, 4.0F, 1e-6F);
}

TEST(InstanceLearner, ApproachTwoUsesMeanDistanceAndMeanIcd) {
  InstanceConfig cfg;
  cfg.approach = NocdApproach::MEAN_DISTANCE;
  auto learner_ptr = make_ab(cfg);
  auto& learner = *learner_ptr;
  AskScratch scratch;
  const Prediction p = learner.ask(QUERY, scratch);
  // OCD_A = 4, OCD_B = (5 + sqrt 41) / 2, mean ICD = 3: NOCD_A = 8 / 5, NOCD_B = (5 + sqrt 41) / 7.
  EXPECT_EQ(p.label.view(), "A");
  EXPECT_NEAR(p.score, 1.6F, 1e-5F);
  EXPECT_EQ(p.runner_up.view(), "B");
  EXPECT_NEAR(p.runner_up_score, static_cast<float>((5.0 + std::sqrt(41.0)) / 7.0), 1e-5F);
}

TEST(InstanceLearner, PlainNearestNeighbourIgnoresSpread) {
  InstanceConfig cfg;
  cfg.normalise = false;
  auto learner_ptr = make_ab(cfg);
  auto& learner = *learner_ptr;
  AskScratch scratch;
  const Prediction p = learner.ask(QUERY, scratch);
  EXPECT_EQ(p.label.view(), "A");
  EXPECT_NEAR(p.score, 3.0F, 1e-5F);
  EXPECT_NEAR(p.runner_up_score, 5.0F, 1e-5F);
}

TEST(InstanceLearner, UnknownWhenMinNocdExceedsThreshold) {
  InstanceConfig cfg;
  cfg.classification_threshold = 1.3F;
  AskScratch scratch;
  auto accepted = make_ab(cfg)->ask(QUERY, scratch);
  EXPECT_FALSE(accepted.unknown);
  EXPECT_EQ(accepted.label.view(), "B");
  cfg.classification_threshold = 1.2F;
  auto rejected = make_ab(cfg)->ask(QUERY, scratch);
  EXPECT_TRUE(rejected.unknown);
  EXPECT_EQ(rejected.category, NO_CATEGORY);
  EXPECT_EQ(rejected.label.view(), "B");  // the best guess is still reported
  EXPECT_NEAR(rejected.score, 1.25F, 1e-5F);
}

TEST(InstanceLearner, SingleViewCategoryBorrowsMeanIcdOfTheOthers) {
  auto learner_ptr = make_ab(InstanceConfig{});
  auto& learner = *learner_ptr;
  const std::vector<float> c{0, 10};
  ASSERT_TRUE(learner.teach("C", batch(c, 2)));
  AskScratch scratch;
  const std::vector<float> q{0, 13};
  const Prediction p = learner.ask(q, scratch);
  EXPECT_EQ(p.label.view(), "C");
  EXPECT_NEAR(p.score, 1.0F, 1e-5F);  // OCD 3 / mean(2, 4)
  EXPECT_NEAR(learner.categories()[2].spread, 3.0F, 1e-6F);

  InstanceConfig lone_cfg;
  lone_cfg.descriptor_length = 2;
  lone_cfg.default_icd = 0.5F;
  InstanceLearner lone(lone_cfg);
  ASSERT_TRUE(lone.teach("C", batch(c, 2)));
  EXPECT_NEAR(lone.ask(q, scratch).score, 6.0F, 1e-5F);  // no category with two views: default ICD
}

TEST(InstanceLearner, DuplicateViewsClampIcdToTheFloor) {
  InstanceConfig cfg;
  cfg.descriptor_length = 2;
  InstanceLearner learner(cfg);
  const std::vector<float> same{1, 1, 1, 1};
  ASSERT_TRUE(learner.teach("D", batch(same, 2)));
  EXPECT_FLOAT_EQ(learner.categories()[0].spread, cfg.min_icd);
  AskScratch scratch;
  EXPECT_TRUE(std::isfinite(learner.ask(std::vector<float>{1, 2}, scratch).score));
}

TEST(InstanceLearner, ChunkSizeDoesNotChangeTheAnswer) {
  InstanceConfig cfg;
  cfg.descriptor_length = 8;
  cfg.approach = NocdApproach::MEAN_DISTANCE;
  InstanceLearner learner(cfg);
  std::vector<float> values;
  for (int v = 0; v < 37; ++v) {
    for (int d = 0; d < 8; ++d) { values.push_back(static_cast<float>((v * 7 + d * 3) % 11)); }
  }
  ASSERT_TRUE(learner.teach("many", batch(values, 8)));
  ASSERT_TRUE(learner.teach("few", DescriptorBatch{std::span<const float>(values).first(24), 8}));
  AskScratch one(1);
  AskScratch big;
  const std::vector<float> q{1, 2, 3, 4, 5, 6, 7, 8};
  const Prediction a = learner.ask(q, one);
  const Prediction b = learner.ask(q, big);
  EXPECT_EQ(a.label, b.label);
  EXPECT_FLOAT_EQ(a.score, b.score);
  EXPECT_FLOAT_EQ(a.runner_up_score, b.runner_up_score);
}

// A: one view (1,0,0); B: (0,1,0) and (0,.5,.5); count_scale 2, so a_A = (2,0,0), a_B = (0,3,1).
TEST(BayesLearner, LogPosteriorMatchesHandComputation) {
  BayesLearner learner(BayesConfig{3, 2.0F});
  ASSERT_TRUE(learner.teach("A", batch({1, 0, 0}, 3)));
  ASSERT_TRUE(learner.teach("B", batch({0, 1, 0, 0, 0.5F, 0.5F}, 3)));
  AskScratch scratch;
  const Prediction p = learner.ask(std::vector<float>{0.5F, 0.5F, 0.0F}, scratch);  // y = (1, 1, 0)
  const double score_a = std::log(1.0 / 3.0) + std::log(3.0 / 5.0) + std::log(1.0 / 5.0);
  const double score_b = std::log(2.0 / 3.0) + std::log(1.0 / 7.0) + std::log(4.0 / 7.0);
  EXPECT_FALSE(p.unknown);
  EXPECT_EQ(p.label.view(), "B");
  EXPECT_NEAR(p.score, score_b, 1e-5);
  EXPECT_EQ(p.runner_up.view(), "A");
  EXPECT_NEAR(p.runner_up_score, score_a, 1e-5);
  EXPECT_EQ(learner.stats().views, 3U);
  // Correct adds one view to A: N_A = 2, a_A = (2,2,0) -> P = (3,3,1)/7, P(A) = 1/2.
  ASSERT_TRUE(learner.correct("A", std::vector<float>{0, 1, 0}));
  const Prediction q = learner.ask(std::vector<float>{0.5F, 0.5F, 0.0F}, scratch);
  EXPECT_EQ(q.label.view(), "A");
  EXPECT_NEAR(q.score, std::log(0.5) + 2.0 * std::log(3.0 / 7.0), 1e-5);
}

TEST(Learners, NothingLearnedIsUnknownAndWrongLengthIsUnknown) {
  InstanceLearner instance(InstanceConfig{4});
  BayesLearner bayes(BayesConfig{4});
  AskScratch scratch;
  for (const Learner* l :
       {static_cast<const Learner*>(&instance), static_cast<const Learner*>(&bayes)}) {
    const Prediction p = l->ask(std::vector<float>{0, 0, 0, 1}, scratch);
    EXPECT_TRUE(p.unknown);
    EXPECT_EQ(p.category, NO_CATEGORY);
    EXPECT_TRUE(p.label.view().empty());
    EXPECT_TRUE(l->ask(std::vector<float>{0, 1}, scratch).unknown);
  }
}

TEST(Learners, OpenEndedCategoriesArriveAfterThousandsOfAsks) {
  InstanceLearner instance(InstanceConfig{4});
  BayesLearner bayes(BayesConfig{4});
  AskScratch scratch;
  for (Learner* l : {static_cast<Learner*>(&instance), static_cast<Learner*>(&bayes)}) {
    ASSERT_TRUE(l->teach("x", batch({1, 0, 0, 0, 0.9F, 0.1F, 0, 0}, 4)));
    ASSERT_TRUE(l->teach("y", batch({0, 1, 0, 0, 0.1F, 0.9F, 0, 0}, 4)));
    for (int i = 0; i < 3000; ++i) {
      ASSERT_EQ(l->ask(std::vector<float>{0, 0, 1, 0}, scratch).category != 2U, true);
    }
    ASSERT_EQ(*l->teach("z", batch({0, 0, 1, 0, 0, 0, 0.9F, 0.1F}, 4)), 2U);
    const Prediction p = l->ask(std::vector<float>{0, 0, 1, 0}, scratch);
    EXPECT_EQ(p.label.view(), "z") << l->kind();
    EXPECT_EQ(l->stats().categories, 3U);
    EXPECT_GE(l->stats().generation, 3U);
  }
}

TEST(Learners, ForgetRemovesACategoryAndKeptPredictionsStayValid) {
  InstanceLearner instance(InstanceConfig{2});
  BayesLearner bayes(BayesConfig{2});
  AskScratch scratch;
  for (Learner* l : {static_cast<Learner*>(&instance), static_cast<Learner*>(&bayes)}) {
    ASSERT_TRUE(l->teach("cup", batch({1, 0}, 2)));
    ASSERT_TRUE(l->teach("plate", batch({0, 1}, 2)));
    const Prediction before = l->ask(std::vector<float>{1, 0}, scratch);
    ASSERT_EQ(before.label.view(), "cup");
    ASSERT_TRUE(l->forget("cup"));
    EXPECT_EQ(before.label.view(), "cup");  // inline label: unaffected by the learner's change
    EXPECT_EQ(l->ask(std::vector<float>{1, 0}, scratch).label.view(), "plate");
    EXPECT_EQ(l->forget("cup").error(), LearnError::UNKNOWN_LABEL);
    EXPECT_EQ(*l->teach("cup", batch({1, 0}, 2)), 2U);  // ids are never reused
  }
}

// Undo: retract takes back exactly the last lesson; every answer is then the one a learner that
// was never given that lesson gives (same label, category, score and runner-up, bit for bit for the
// instance learner; the Bayes model within rounding of the subtraction).
TEST(Learners, RetractLeavesTheLearnerAsIfTheLessonWasNeverGiven) {
  const std::vector<float> cup1{1, 0, 0.9F, 0.1F};
  const std::vector<float> cup2{0.2F, 0.8F};  // the lesson to take back
  const std::vector<float> plate{0, 1, 0.1F, 0.9F};
  const std::vector<std::vector<float>> queries{{1, 0}, {0, 1}, {0.3F, 0.7F}, {0.5F, 0.5F}};
  for (int kind = 0; kind < 2; ++kind) {
    auto make = [kind]() -> std::unique_ptr<Learner> {
      if (kind == 0) return std::make_unique<InstanceLearner>(InstanceConfig{2});
      return std::make_unique<BayesLearner>(BayesConfig{2});
    };
    auto undone = make();
    auto never = make();
    for (Learner* l : {undone.get(), never.get()}) {
      ASSERT_TRUE(l->teach("cup", batch(cup1, 2)));
      ASSERT_TRUE(l->teach("plate", batch(plate, 2)));
    }
    ASSERT_TRUE(undone->teach("cup", batch(cup2, 2)));
    ASSERT_EQ(undone->stats().views, 5U);
    ASSERT_TRUE(undone->retract("cup", batch(cup2, 2))) << kind;
    EXPECT_EQ(undone->stats().views, never->stats().views);
    AskScratch a;
    AskScratch b;
    for (const auto& q : queries) {
      const Prediction got = undone->ask(q, a);
      const Prediction want = never->ask(q, b);
      EXPECT_EQ(got.label.view(), want.label.view()) << kind;
      EXPECT_EQ(got.category, want.category);
      EXPECT_EQ(got.unknown, want.unknown);
      EXPECT_NEAR(got.score, want.score, kind == 0 ? 0.0F : 1e-5F * (1.0F + std::abs(want.score)));
      EXPECT_EQ(got.runner_up.view(), want.runner_up.view());
    }
  }
}

TEST(Learners, RetractRefusesViewsThatAreNotTheLastOnesAndChangesNothing) {
  InstanceLearner instance(InstanceConfig{2});
  BayesLearner bayes(BayesConfig{2});
  for (Learner* l : {static_cast<Learner*>(&instance), static_cast<Learner*>(&bayes)}) {
    ASSERT_TRUE(l->teach("cup", batch({1, 0}, 2)));
    ASSERT_TRUE(l->teach("cup", batch({0.5F, 0.5F}, 2)));
    const std::uint64_t generation = l->stats().generation;
    EXPECT_EQ(l->retract("bowl", batch({1, 0}, 2)).error(), LearnError::UNKNOWN_LABEL);
    EXPECT_EQ(l->retract("cup", batch({1, 0, 0.5F, 0.5F, 1, 0}, 2)).error(),
              LearnError::NOT_LAST_VIEWS);  // more views than the category has
    EXPECT_EQ(l->retract("cup", batch({}, 2)).error(), LearnError::NO_VIEWS);
    EXPECT_EQ(l->retract("cup", batch({1, 0, 1}, 3)).error(), LearnError::WRONG_LENGTH);
    EXPECT_EQ(l->stats().generation, generation);  // nothing was published
    EXPECT_EQ(l->stats().views, 2U);
  }
  // The instance learner keeps every view, so it can tell a view that is not the last one.
  EXPECT_EQ(instance.retract("cup", batch({1, 0}, 2)).error(), LearnError::NOT_LAST_VIEWS);
  EXPECT_EQ(instance.retract("cup", batch({0.5F, 0.50001F}, 2)).error(),
            LearnError::NOT_LAST_VIEWS);
  EXPECT_EQ(instance.stats().views, 2U);
}

TEST(Learners, RetractingEveryViewRemovesTheCategory) {
  InstanceLearner instance(InstanceConfig{2});
  BayesLearner bayes(BayesConfig{2});
  AskScratch scratch;
  for (Learner* l : {static_cast<Learner*>(&instance), static_cast<Learner*>(&bayes)}) {
    ASSERT_TRUE(l->teach("plate", batch({0, 1}, 2)));
    ASSERT_TRUE(l->teach("cup", batch({1, 0, 0.9F, 0.1F}, 2)));
    ASSERT_TRUE(l->retract("cup", batch({1, 0, 0.9F, 0.1F}, 2)));
    ASSERT_EQ(l->categories().size(), 1U);
    EXPECT_EQ(l->categories()[0].label.view(), "plate");
    EXPECT_EQ(l->ask(std::vector<float>{1, 0}, scratch).label.view(), "plate");
    EXPECT_EQ(l->retract("cup", batch({1, 0}, 2)).error(), LearnError::UNKNOWN_LABEL);
    EXPECT_EQ(*l->teach("cup", batch({1, 0}, 2)), 2U);  // ids are never reused
  }
}

TEST(Learners, RestoreGivesTheSameAnswersAsTeaching) {
  const std::vector<float> a{0, 0, 2, 0};
  const std::vector<float> b{10, 0, 10, 4};
  auto taught = make_ab(InstanceConfig{});
  InstanceLearner restored(InstanceConfig{2});
  const std::vector<RestoredCategory> cats{{7, "B", batch(b, 2), {}, 2},
                                           {3, "A", batch(a, 2), {}, 2}};
  ASSERT_TRUE(restored.restore(cats, 20));
  AskScratch scratch;
  const Prediction p = restored.ask(QUERY, scratch);
  EXPECT_EQ(p.label.view(), taught->ask(QUERY, scratch).label.view());
  EXPECT_EQ(p.category, 7U);
  EXPECT_NEAR(p.score, 1.25F, 1e-5F);
  EXPECT_EQ(*restored.teach("new", batch(a, 2)), 20U);

  BayesLearner bayes(BayesConfig{2});
  const std::vector<double> acc{2.0, 0.0};
  const std::vector<RestoredCategory> model{{4, "A", {}, acc, 2}};
  ASSERT_TRUE(bayes.restore(model, 0));
  EXPECT_EQ(bayes.stats().views, 2U);
  EXPECT_EQ(*bayes.teach("B", batch({0, 1}, 2)), 5U);
}

TEST(Learners, EveryLearnErrorIsReported) {
  InstanceLearner instance(InstanceConfig{2});
  BayesLearner bayes(BayesConfig{2});
  const float nan = std::nanf("");
  EXPECT_EQ(instance.teach("", batch({1, 0}, 2)).error(), LearnError::EMPTY_LABEL);
  EXPECT_TRUE(instance.teach(std::string(63, 'a'), batch({1, 0}, 2)));
  EXPECT_EQ(instance.teach(std::string(64, 'a'), batch({1, 0}, 2)).error(),
            LearnError::LABEL_TOO_LONG);
  for (const std::string& bad :
       {std::string("mug\nbowl"), std::string("a\tb"), std::string("a\0b", 3), std::string("\xC3"),
        std::string("\xC0\xAF"), std::string("\xED\xA0\x80"), std::string("x\x7F"),
        std::string("\xC2\x85")}) {
    EXPECT_EQ(instance.teach(bad, batch({1, 0}, 2)).error(), LearnError::BAD_CHARACTERS) << bad;
  }
  InstanceLearner utf8(InstanceConfig{2});  // UTF-8 beyond ASCII is fine
  EXPECT_TRUE(utf8.teach("tasse \xC3\xA0 caf\xC3\xA9", batch({1, 0}, 2)));
  EXPECT_EQ(instance.teach("a", batch({}, 2)).error(), LearnError::NO_VIEWS);
  EXPECT_EQ(instance.teach("a", batch({1, 0, 1}, 3)).error(), LearnError::WRONG_LENGTH);
  EXPECT_EQ(instance.teach("a", batch({1, 0, 1}, 2)).error(), LearnError::WRONG_LENGTH);
  EXPECT_EQ(instance.teach("a", batch({1, nan}, 2)).error(), LearnError::NOT_FINITE);
  EXPECT_TRUE(instance.teach("neg", batch({-1, 0}, 2)));  // L2 works on any finite vector
  EXPECT_EQ(bayes.teach("neg", batch({-1, 0}, 2)).error(), LearnError::NEGATIVE_VALUE);
  EXPECT_EQ(bayes.forget("none").error(), LearnError::UNKNOWN_LABEL);
  const std::vector<float> v{1, 0};
  const std::vector<RestoredCategory> twice{{1, "a", batch(v, 2), {}, 1},
                                            {1, "b", batch(v, 2), {}, 1}};
  EXPECT_EQ(instance.restore(twice, 0).error(), LearnError::DUPLICATE_ID);
  const std::vector<RestoredCategory> same_label{{1, "a", batch(v, 2), {}, 1},
                                                 {2, "a", batch(v, 2), {}, 1}};
  EXPECT_EQ(bayes.restore(same_label, 0).error(), LearnError::DUPLICATE_ID);
  const std::vector<double> acc{1.0, 0.0};
  const std::vector<RestoredCategory> model_only{{1, "a", {}, acc, 1}};
  EXPECT_EQ(instance.restore(model_only, 0).error(),
            LearnError::NO_VIEWS);  // instance needs the views
  EXPECT_TRUE(bayes.restore(model_only, 0));
  EXPECT_EQ(instance.stats().categories, 2U);  // refused restores changed nothing
  EXPECT_STRNE(to_string(LearnError::DUPLICATE_ID), "unknown learn error");
}

}  // namespace
}  // namespace orthoflow::learning
