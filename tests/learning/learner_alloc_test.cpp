// ask() allocates nothing after warm-up: global operator new/delete are replaced in this binary and
// counted while g_counting is set (the idea of tests/engine/engine_alloc_test.cpp).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "learning/bayes_learner.hpp"
#include "learning/instance_learner.hpp"

#include "tests/support/counting_new.hpp"  // the one TU of this binary that replaces operator new

using orthoflow::test::g_allocations;
using orthoflow::test::g_counting;

namespace orthoflow::learning {
namespace {

constexpr std::size_t LENGTH = 75;

std::vector<float> histogram(std::size_t seed) {
  std::vector<float> v(LENGTH, 0.0F);
  for (std::size_t b = 0; b < 3; ++b) {
    v[b * 25 + seed % 25] = 0.7F;
    v[b * 25 + (seed * 7 + 3) % 25] += 0.3F;
  }
  return v;
}

// Teaches 20 categories of 30 views, warms up, then counts allocations over 500 asks.
std::uint64_t allocations_during_asks(Learner& learner) {
  for (std::size_t k = 0; k < 20; ++k) {
    std::vector<float> views;
    for (std::size_t v = 0; v < 30; ++v) {
      const auto h = histogram(k + v * 31);
      views.insert(views.end(), h.begin(), h.end());
    }
    EXPECT_TRUE(learner.teach("c" + std::to_string(k), DescriptorBatch{views, LENGTH}));
  }
  AskScratch scratch(16);  // smaller than a category: the chunked walk is exercised too
  const auto query = histogram(5);
  float sink = learner.ask(query, scratch).score;
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < 500; ++i) { sink += learner.ask(query, scratch).score; }
  const Prediction p = learner.ask(query, scratch);
  g_counting = false;
  EXPECT_FALSE(p.label.view().empty());
  EXPECT_TRUE(sink == sink || sink != sink);  // keeps the asks observable
  return g_allocations.load();
}

TEST(LearnerAllocations, InstanceAskAllocatesNothing) {
  for (const NocdApproach approach : {NocdApproach::MIN_DISTANCE, NocdApproach::MEAN_DISTANCE}) {
    InstanceConfig cfg;
    cfg.descriptor_length = LENGTH;
    cfg.approach = approach;
    InstanceLearner learner(cfg);
    EXPECT_EQ(allocations_during_asks(learner), 0U);
  }
}

TEST(LearnerAllocations, BayesAskAllocatesNothing) {
  BayesLearner learner(BayesConfig{LENGTH, 100.0F});
  EXPECT_EQ(allocations_during_asks(learner), 0U);
}

TEST(LearnerAllocations, TheCounterSeesAllocations) {
  g_allocations = 0;
  g_counting = true;
  auto* p = new std::vector<float>(10);
  g_counting = false;
  delete p;
  EXPECT_GE(g_allocations.load(), 1U);  // so a zero above is a real zero
}

}  // namespace
}  // namespace orthoflow::learning
