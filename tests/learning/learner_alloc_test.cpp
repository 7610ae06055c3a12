// ask() allocates nothing after warm-up: global operator new/delete are replaced in this binary and
// counted while g_counting is set (the idea of tests/engine/engine_alloc_test.cpp).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>

#include "learning/bayes_learner.hpp"
#include "learning/instance_learner.hpp"
#include "learning/local_lda_learner.hpp"
#include "learning/spin_set_learner.hpp"

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

// Teaches 20 categories of @p per_category views made by @p make(seed), prepares a scratch, warms
// up, then counts allocations over @p asks asks.
template <class MakeView>
std::uint64_t allocations_during_asks(Learner& learner, MakeView make, std::size_t per_category,
                                      int asks) {
  for (std::size_t k = 0; k < 20; ++k) {
    std::vector<float> views;
    for (std::size_t v = 0; v < per_category; ++v) {
      const auto h = make(k + v * 31);
      views.insert(views.end(), h.begin(), h.end());
    }
    EXPECT_TRUE(learner.teach("c" + std::to_string(k),
                              DescriptorBatch{views, views.size() / per_category}));
  }
  AskScratch scratch(16);  // smaller than a category: the chunked walk is exercised too
  learner.prepare(scratch);
  const auto query = make(5);
  float sink = learner.ask(query, scratch).score;
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < asks; ++i) { sink += learner.ask(query, scratch).score; }
  const Prediction p = learner.ask(query, scratch);
  g_counting = false;
  EXPECT_FALSE(p.unknown);
  EXPECT_TRUE(std::isfinite(sink));  // keeps the asks observable
  return g_allocations.load();
}

std::uint64_t allocations_during_asks(Learner& learner) {
  return allocations_during_asks(learner, histogram, 30, 500);
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

// Local LDA samples the target in every category's topics: with its scratch prepared once, asking
// allocates nothing either (20 categories of 10 views of 75 words' counts).
TEST(LearnerAllocations, LocalLdaAskAllocatesNothing) {
  for (const LocalLdaDecision d :
       {LocalLdaDecision::NEAREST, LocalLdaDecision::NOCD_2, LocalLdaDecision::LIKELIHOOD}) {
    LocalLdaConfig cfg;
    cfg.words = LENGTH;
    cfg.topics.topics = 8;
    cfg.max_words = 1000;
    cfg.decision = d;
    LocalLdaLearner learner(cfg);
    const auto counts = [](std::size_t seed) {
      std::vector<float> v = histogram(seed);
      for (float& x : v) x = std::round(x * 40.0F);
      return v;
    };
    EXPECT_EQ(allocations_during_asks(learner, counts, 10, 50), 0U) << learner.kind();
  }
}

// Sets of spin images: D(T, O) for every stored view, with the scratch's distances prepared for the
// largest set (20 categories of 6 views of up to 16 images of width 2).
TEST(LearnerAllocations, SpinSetAskAllocatesNothing) {
  for (const NocdApproach approach : {NocdApproach::MIN_DISTANCE, NocdApproach::MEAN_DISTANCE}) {
    SpinSetConfig cfg;
    cfg.set.features.spin.image_width = 2;
    cfg.set.max_keypoints = 16;
    cfg.approach = approach;
    SpinSetLearner learner(cfg);
    const auto set = [&cfg](std::size_t seed) {
      std::vector<float> v(cfg.set.length(), 0.0F);
      const std::size_t n = 1 + seed % 16, dims = cfg.set.image_values();
      v[0] = static_cast<float>(n);
      for (std::size_t i = 0; i < n * dims; ++i)
        v[1 + i] = static_cast<float>((seed * 13 + i * 7) % 11) / 11.0F;
      return v;
    };
    EXPECT_EQ(allocations_during_asks(learner, set, 6, 50), 0U) << learner.kind();
  }
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
