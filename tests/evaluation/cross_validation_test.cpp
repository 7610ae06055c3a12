// Metrics on hand-counted confusion matrices, stratified folds, and k-fold cross-validation on
// hand-made datasets (separable: accuracy 1; two identical categories: every view of one is taken
// for the other).
#include <gtest/gtest.h>

#include <set>

#include "evaluation/cross_validation.hpp"
#include "tests/evaluation/eval_fixtures.hpp"

namespace orthoflow::evaluation {
namespace {

using testing::E0;
using testing::E1;
using testing::E2;

TEST(Metrics, HandCountedConfusion) {
  // truth 0: 3 right, 1 as class 1; truth 1: 2 right, 1 unknown; class 2 never asked, predicted
  // once (from 0).
  Confusion c(3);
  for (int i = 0; i < 3; ++i) { c.add(0, 0); }
  c.add(0, 1);
  c.add(0, 2);
  c.add(1, 1);
  c.add(1, 1);
  c.add(1, std::nullopt);
  const Scores s = score(c);
  EXPECT_EQ(s.answers, 8U);
  EXPECT_EQ(s.unknown, 1U);
  EXPECT_DOUBLE_EQ(s.accuracy, 5.0 / 8.0);
  EXPECT_DOUBLE_EQ(s.micro_recall, 5.0 / 8.0);
  EXPECT_DOUBLE_EQ(s.micro_precision, 5.0 / 7.0);
  // precision: class 0 = 3/3, class 1 = 2/3, class 2 = 0/1 -> mean over 3 classes.
  EXPECT_DOUBLE_EQ(s.macro_precision, (1.0 + 2.0 / 3.0 + 0.0) / 3.0);
  // recall: class 0 = 3/5, class 1 = 2/3; class 2 never asked, left out.
  EXPECT_DOUBLE_EQ(s.macro_recall, (3.0 / 5.0 + 2.0 / 3.0) / 2.0);
}

TEST(Metrics, EmptyConfusionAndMeanStd) {
  const Scores s = score(Confusion(4));
  EXPECT_EQ(s.answers, 0U);
  EXPECT_EQ(s.accuracy, 0.0);
  EXPECT_EQ(mean_std({}).mean, 0.0);
  const MeanStd m = mean_std({1.0, 2.0, 3.0, 4.0});
  EXPECT_DOUBLE_EQ(m.mean, 2.5);
  EXPECT_NEAR(m.std, 1.2909944487358056, 1e-12);
  EXPECT_EQ(mean_std({7.0}).std, 0.0);
}

TEST(Folds, StratifiedDeterministicAndSeeded) {
  const auto h = testing::hand_made({{"a", 10, E0}, {"b", 13, E1}, {"c", 3, E2}});
  auto f1 = make_folds(h.dataset, 10, 42);
  auto f2 = make_folds(h.dataset, 10, 42);
  auto f3 = make_folds(h.dataset, 10, 43);
  ASSERT_TRUE(f1 && f2 && f3);
  EXPECT_EQ(f1->fold_of_view, f2->fold_of_view);
  EXPECT_NE(f1->fold_of_view, f3->fold_of_view);
  // Category a (10 views): exactly one per fold; b (13): every fold 1 or 2; c (3): 3 distinct
  // folds.
  for (std::uint32_t c = 0; c < 3; ++c) {
    std::vector<int> per_fold(10, 0);
    for (const std::size_t v : h.dataset.views_of(c)) { per_fold[f1->fold_of_view[v]] += 1; }
    for (const int n : per_fold) {
      EXPECT_LE(n, 2);
      if (c == 0) { EXPECT_EQ(n, 1); }
    }
  }
}

TEST(Folds, Errors) {
  const auto h = testing::hand_made({{"a", 10, E0}, {"b", 1, E1}});
  auto one_view = make_folds(h.dataset, 10, 1);
  ASSERT_FALSE(one_view);
  EXPECT_EQ(one_view.error().code, EvalError::Code::TOO_FEW_VIEWS);
  EXPECT_NE(one_view.error().message.find("'b'"), std::string::npos);
  auto one_fold = make_folds(h.dataset, 1, 1);
  ASSERT_FALSE(one_fold);
  EXPECT_EQ(one_fold.error().code, EvalError::Code::BAD_CONFIG);
}

TEST(CrossValidation, SeparableCategoriesAreAllRight) {
  const auto h = testing::hand_made({{"a", 10, E0}, {"b", 12, E1}, {"c", 5, E2}});
  auto folds = make_folds(h.dataset, 5, 7);
  ASSERT_TRUE(folds);
  for (const Variant& v : {testing::nn_variant(), testing::bayes_variant()}) {
    const CvResult r = cross_validate(h.dataset, *folds, h.table, h.table, v);
    EXPECT_DOUBLE_EQ(r.scores.accuracy, 1.0) << v.name();
    EXPECT_EQ(r.confusion.at(1, 1), 12U);
    EXPECT_EQ(r.confusion.total(), 27U);
    EXPECT_EQ(r.fold_accuracy.size(), 5U);
  }
}

// a and b have identical views: nearest neighbour ties go to the category taught first (a), so
// every b view is answered "a": accuracy 10/20, recall a = 1, recall b = 0.
TEST(CrossValidation, IdenticalCategoriesAreConfused) {
  const auto h = testing::hand_made({{"a", 10, E0}, {"b", 10, E0}});
  auto folds = make_folds(h.dataset, 10, 3);
  ASSERT_TRUE(folds);
  const CvResult r = cross_validate(h.dataset, *folds, h.table, h.table, testing::nn_variant());
  EXPECT_DOUBLE_EQ(r.scores.accuracy, 0.5);
  EXPECT_EQ(r.confusion.at(1, 0), 10U);
  EXPECT_DOUBLE_EQ(r.scores.macro_recall, 0.5);
}

// Perturbed test views: training on clean rows, testing on rows of another table (here: the test
// table swaps the descriptors of a and b, so every answer is wrong).
TEST(CrossValidation, TestTableIsTheOneAsked) {
  const auto h = testing::hand_made({{"a", 6, E0}, {"b", 6, E1}});
  const auto swapped = testing::hand_made({{"a", 6, E1}, {"b", 6, E0}});
  auto folds = make_folds(h.dataset, 3, 1);
  ASSERT_TRUE(folds);
  const CvResult r =
      cross_validate(h.dataset, *folds, h.table, swapped.table, testing::nn_variant());
  EXPECT_DOUBLE_EQ(r.scores.accuracy, 0.0);
}

}  // namespace
}  // namespace orthoflow::evaluation
