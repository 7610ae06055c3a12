// One thread teaches while several ask: every answer must come from one consistent snapshot (its
// label names a category that existed, its label and id agree, generations and counts never go
// backwards).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "learning/bayes_learner.hpp"
#include "learning/instance_learner.hpp"
#include "learning/snapshot_cell.hpp"

namespace orthoflow::learning {
namespace {

constexpr std::size_t LENGTH = 16;
constexpr std::size_t CATEGORIES = 12;
constexpr int ROUNDS = 30;
constexpr int ASKERS = 3;

// Category k: a histogram peaked on bin k; round r shifts a little weight to bin k + 1.
std::vector<float> view(std::size_t k, int r) {
  std::vector<float> v(LENGTH, 0.0F);
  const float w = 0.01F * static_cast<float>(r % 5);
  v[k] = 1.0F - w;
  v[(k + 1) % LENGTH] = w;
  return v;
}

std::string label_of(std::size_t k) { return "c" + std::to_string(k); }

void ask_until_done(const Learner& learner, const std::atomic<std::size_t>& published,
                    const std::atomic<bool>& done, bool exact, std::atomic<int>& failures,
                    std::atomic<long>& asks) {
  AskScratch scratch(4);  // small chunks: several kernel calls per category
  std::uint64_t last_generation = 0;
  std::size_t last_categories = 0;
  for (std::size_t i = 0; !done.load(std::memory_order_acquire); ++i) {
    const std::size_t before = published.load(std::memory_order_acquire);
    const std::size_t k = before == 0 ? 0 : i % before;
    const Prediction p = learner.ask(view(k, 0), scratch);
    const std::size_t after = published.load(std::memory_order_acquire);
    const std::size_t categories = learner.stats().categories;
    bool ok = p.generation >= last_generation && categories >= last_categories;
    if (before > 0) {
      ok = ok && !p.unknown && p.category < after && p.label.view() == label_of(p.category);
      ok = ok && (!exact || p.category == k);
    }
    if (!ok && failures.fetch_add(1) == 0) {
      ADD_FAILURE() << "asked c" << k << " (published " << before << ".." << after << "): got "
                    << p.label.view() << " id " << p.category << " unknown " << p.unknown
                    << " generation " << p.generation << " (last " << last_generation
                    << "), categories " << categories << " (last " << last_categories << ")";
    }
    last_generation = p.generation;
    last_categories = categories;
    asks.fetch_add(1, std::memory_order_relaxed);
  }
}

void run(Learner& learner, bool exact) {
  std::atomic<std::size_t> published{0};
  std::atomic<bool> done{false};
  std::atomic<int> failures{0};
  std::atomic<long> asks{0};
  std::vector<std::thread> askers;
  for (int t = 0; t < ASKERS; ++t) {
    askers.emplace_back([&] { ask_until_done(learner, published, done, exact, failures, asks); });
  }
  for (int r = 0; r < ROUNDS; ++r) {
    for (std::size_t k = 0; k < CATEGORIES; ++k) {
      // Interleave for sure: a few asks between consecutive teaches.
      for (const long seen = asks.load(); asks.load() < seen + 2;) {
        std::this_thread::sleep_for(std::chrono::microseconds(50));
      }
      const std::vector<float> v = view(k, r);
      ASSERT_EQ(*learner.teach(label_of(k), DescriptorBatch{v, LENGTH}), k);
      if (r == 0) {
        published.store(k + 1, std::memory_order_release);
      }  // teach returned: visible to the next ask
    }
  }
  done.store(true, std::memory_order_release);
  for (std::thread& t : askers) { t.join(); }
  EXPECT_EQ(failures.load(), 0) << learner.kind() << ": " << asks.load() << " asks";
  EXPECT_GE(asks.load(), 2L * ROUNDS * static_cast<long>(CATEGORIES));
  EXPECT_EQ(learner.stats().views, CATEGORIES * ROUNDS);
  EXPECT_LE(learner.stats().retired_pending, SNAPSHOT_READER_SLOTS + 1);
}

TEST(LearnerConcurrency, InstanceAsksSeeConsistentSnapshotsWhileTeaching) {
  InstanceConfig cfg;
  cfg.descriptor_length = LENGTH;
  cfg.normalise = false;  // the query equals a stored view: distance 0, its own category wins
  InstanceLearner learner(cfg);
  run(learner, true);
}

TEST(LearnerConcurrency, BayesAsksSeeConsistentSnapshotsWhileTeaching) {
  BayesLearner learner(BayesConfig{LENGTH, 50.0F});
  run(learner, true);
}

}  // namespace
}  // namespace orthoflow::learning
