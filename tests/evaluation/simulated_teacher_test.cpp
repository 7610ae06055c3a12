// The simulated teacher (thesis Algorithms 7.1 and 7.2) on hand-made datasets whose NLC, QCI, GCA,
// APA, AIC and stopping condition are worked out in the comments.
#include <gtest/gtest.h>

#include <algorithm>

#include "evaluation/simulated_teacher.hpp"
#include "tests/evaluation/eval_fixtures.hpp"

namespace orthoflow::evaluation {
namespace {

using testing::E0;
using testing::E1;
using testing::E2;
using testing::E3;

std::vector<std::uint32_t> identity(std::size_t n) {
  std::vector<std::uint32_t> o(n);
  for (std::uint32_t i = 0; i < n; ++i) { o[i] = i; }
  return o;
}

// Three separable categories, order 0, 1, 2. Category 0 is known after its introduction.
// Introducing 1 (n = 2): ask 0 (right, k = 1 < n), ask 1 (right, k = 2, s = 1) -> learned: 2
// iterations. Introducing 2 (n = 3): ask 0, 1, 2 -> learned after 3. No category left: lack of
// data. QCI 5, NLC 3, all answers right, 9 views stored for 3 categories.
TEST(SimulatedTeacher, SeparableCategoriesAreAllLearnedUntilLackOfData) {
  for (const Variant& variant : {testing::nn_variant(), testing::bayes_variant()}) {
    const auto h = testing::hand_made({{"a", 6, E0}, {"b", 6, E1}, {"c", 6, E2}});
    const TeacherRun run =
        run_teacher(h.dataset, h.table, variant, identity(3), TeacherConfig{}, 1);
    EXPECT_EQ(run.nlc, 3U) << variant.name();
    EXPECT_EQ(run.qci, 5U);
    EXPECT_EQ(run.stop, TeacherStop::LACK_OF_DATA);
    EXPECT_DOUBLE_EQ(run.gca, 1.0);
    EXPECT_DOUBLE_EQ(run.apa, 1.0);
    EXPECT_DOUBLE_EQ(run.aic, 3.0);
    ASSERT_EQ(run.curve.size(), 3U);
    EXPECT_EQ(run.curve[1].iteration, 2U);
    EXPECT_EQ(run.curve[2].iteration, 5U);
    EXPECT_EQ(run.curve[2].learned, 3U);
  }
}

// Two categories with identical views: each answer names the same category, so the answers
// alternate right / wrong and no window of k >= 2 answers ever exceeds 0.5 < tau. The breakpoint
// (10 here) ends the experiment with only the first category learned; the 5 wrong answers were
// corrected (taught back).
TEST(SimulatedTeacher, IndistinguishableCategoryReachesTheBreakpoint) {
  const auto h = testing::hand_made({{"a", 20, E0}, {"b", 20, E0}});
  TeacherConfig cfg;
  cfg.breakpoint = 10;
  const TeacherRun run =
      run_teacher(h.dataset, h.table, testing::nn_variant(), identity(2), cfg, 3);
  EXPECT_EQ(run.stop, TeacherStop::BREAKPOINT);
  EXPECT_EQ(run.nlc, 1U);
  EXPECT_EQ(run.qci, 10U);
  EXPECT_DOUBLE_EQ(run.gca, 0.5);
  EXPECT_DOUBLE_EQ(run.aic, (6.0 + 5.0) / 2.0);
  EXPECT_LT(run.apa, 0.67);
}

// A category runs out of unseen views: b has 4 views (3 taught, 1 asked). Introducing c (n = 3):
// ask a (right), then b has no unseen view left -> lack of data with 2 categories learned after 3
// iterations.
TEST(SimulatedTeacher, ExhaustedCategoryStopsWithLackOfData) {
  const auto h = testing::hand_made({{"a", 6, E0}, {"b", 4, E1}, {"c", 6, E2}});
  const TeacherRun run =
      run_teacher(h.dataset, h.table, testing::nn_variant(), identity(3), TeacherConfig{}, 5);
  EXPECT_EQ(run.stop, TeacherStop::LACK_OF_DATA);
  EXPECT_EQ(run.nlc, 2U);
  EXPECT_EQ(run.qci, 3U);
}

// The order is respected: with order (2, 0, 1) the first learned point is category 2 at iteration 0
// and the protocol still learns all three.
TEST(SimulatedTeacher, CategoryOrderIsFollowed) {
  const auto h = testing::hand_made({{"a", 6, E0}, {"b", 6, E1}, {"c", 6, E2}});
  const std::vector<std::uint32_t> order{2, 0, 1};
  const TeacherRun run =
      run_teacher(h.dataset, h.table, testing::nn_variant(), order, TeacherConfig{}, 1);
  EXPECT_EQ(run.nlc, 3U);
  EXPECT_EQ(run.qci, 5U);
}

// Context change (Algorithm 7.2) with context A = the first 2 categories. A: 0 known, 1 learned
// after 2 iterations. Switch. B: introducing 2 (n = 3), only 2 is in context: asked 3 times until k
// >= n. Introducing 3 (n = 4): 2, 3, 2, 3 -> learned. QCI 2 + 3 + 4 = 9; 2 learned in A, 2 in B.
TEST(SimulatedTeacher, ContextChangeAsksOnlyTheCurrentContext) {
  const auto h = testing::hand_made({{"a", 10, E0}, {"b", 10, E1}, {"c", 10, E2}, {"d", 10, E3}});
  TeacherConfig cfg;
  cfg.context_a = 2;
  const TeacherRun run =
      run_teacher(h.dataset, h.table, testing::nn_variant(), identity(4), cfg, 9);
  EXPECT_TRUE(run.switched);
  EXPECT_EQ(run.learned_a, 2U);
  EXPECT_EQ(run.learned_b, 2U);
  EXPECT_EQ(run.qci, 9U);
  EXPECT_EQ(run.nlc, 4U);
  EXPECT_EQ(run.stop, TeacherStop::LACK_OF_DATA);
}

// The same dataset without context change: every known category is asked in turn.
TEST(SimulatedTeacher, WithoutContextChangeEveryKnownCategoryIsAsked) {
  const auto h = testing::hand_made({{"a", 10, E0}, {"b", 10, E1}, {"c", 10, E2}, {"d", 10, E3}});
  const TeacherRun run =
      run_teacher(h.dataset, h.table, testing::nn_variant(), identity(4), TeacherConfig{}, 9);
  // 2 (n = 2) + 3 (n = 3) + 4 (n = 4) iterations, every category asked in turn.
  EXPECT_EQ(run.qci, 9U);
  EXPECT_FALSE(run.switched);
  EXPECT_EQ(run.learned_a, 4U);
}

TEST(SimulatedTeacher, SameSeedSameRunAndOrdersArePermutations) {
  const auto h = testing::hand_made({{"a", 20, E0}, {"b", 20, E0}, {"c", 20, E2}});
  TeacherConfig cfg;
  cfg.breakpoint = 30;
  const TeacherRun r1 = run_teacher(h.dataset, h.table, testing::nn_variant(), identity(3), cfg, 4);
  const TeacherRun r2 = run_teacher(h.dataset, h.table, testing::nn_variant(), identity(3), cfg, 4);
  EXPECT_EQ(r1.qci, r2.qci);
  EXPECT_EQ(r1.gca, r2.gca);
  EXPECT_EQ(r1.apa, r2.apa);
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    std::vector<std::uint32_t> order = category_order(7, seed);
    std::sort(order.begin(), order.end());
    EXPECT_EQ(order, identity(7));
  }
  EXPECT_NE(category_order(7, 1), category_order(7, 2));
  EXPECT_EQ(category_order(7, 1), category_order(7, 1));
}

}  // namespace
}  // namespace orthoflow::evaluation
