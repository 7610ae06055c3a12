// ask() latency against 100, 1k and 10k stored 675-value (15-bin GOOD) views for the instance
// learner (approach I, L2) and naive Bayes (10 views per category, so N/10 categories), and teach
// latency: the learner alone and the perceptual memory including its synced LevelDB write.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "learning/bayes_learner.hpp"
#include "learning/instance_learner.hpp"
#include "learning/perceptual_memory.hpp"

namespace ol = orthoflow::learning;

namespace {

constexpr std::size_t DIMS = 675;
constexpr std::size_t VIEWS_PER_CATEGORY = 10;

// A random normalised histogram (three 225-bin blocks summing to 1 each).
std::vector<float> histogram(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  std::vector<float> v(DIMS);
  for (std::size_t b = 0; b < 3; ++b) {
    float sum = 0.0F;
    for (std::size_t i = 0; i < DIMS / 3; ++i) {
      sum += v[b * DIMS / 3 + i] = u(rng) * u(rng) * u(rng);
    }
    for (std::size_t i = 0; i < DIMS / 3; ++i) { v[b * DIMS / 3 + i] /= sum; }
  }
  return v;
}

void fill(ol::Learner& learner, std::size_t views) {
  std::mt19937 rng(6);
  for (std::size_t c = 0; c < views / VIEWS_PER_CATEGORY; ++c) {
    std::vector<float> batch;
    for (std::size_t v = 0; v < VIEWS_PER_CATEGORY; ++v) {
      const auto h = histogram(rng);
      batch.insert(batch.end(), h.begin(), h.end());
    }
    (void)learner.teach("c" + std::to_string(c), ol::DescriptorBatch{batch, DIMS});
  }
}

template <class L, class Config>
void BM_ask(benchmark::State& state, Config cfg) {
  cfg.descriptor_length = DIMS;
  L learner(cfg);
  const auto views = static_cast<std::size_t>(state.range(0));
  fill(learner, views);
  std::mt19937 rng(99);
  const auto query = histogram(rng);
  ol::AskScratch scratch;
  for (auto _ : state) {
    const ol::Prediction p = learner.ask(query, scratch);
    benchmark::DoNotOptimize(p.score);
  }
  state.counters["views"] = static_cast<double>(views);
  state.counters["categories"] = static_cast<double>(learner.stats().categories);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(views));
}

void BM_ask_instance(benchmark::State& state) {
  BM_ask<ol::InstanceLearner>(state, ol::InstanceConfig{});
}
void BM_ask_bayes(benchmark::State& state) { BM_ask<ol::BayesLearner>(state, ol::BayesConfig{}); }

// Teaching one view into a category of ~range(0) views (learner only: copy-on-write + ICD update).
void BM_teach_instance(benchmark::State& state) {
  ol::InstanceConfig cfg;
  cfg.descriptor_length = DIMS;
  ol::InstanceLearner learner(cfg);
  std::mt19937 rng(3);
  const auto base = static_cast<std::size_t>(state.range(0));
  for (std::size_t v = 0; v < base; ++v) {
    (void)learner.teach("big", ol::DescriptorBatch{histogram(rng), DIMS});
  }
  const auto view = histogram(rng);
  for (auto _ : state) {
    benchmark::DoNotOptimize(learner.teach("big", ol::DescriptorBatch{view, DIMS}));
  }
}

// One teach of one view through the perceptual memory: encode, one WriteBatch with sync=true,
// learner update.
void BM_teach_memory_synced(benchmark::State& state) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "orthoflow_learning_bench";
  std::filesystem::remove_all(dir);
  ol::MemoryConfig cfg;
  cfg.learner = state.range(0) == 0 ? ol::LearnerKind::INSTANCE : ol::LearnerKind::BAYES;
  {
    auto memory_result = ol::PerceptualMemory::open(dir, cfg);
    if (!memory_result) {
      state.SkipWithError(memory_result.error().to_string().c_str());
      return;
    }
    std::mt19937 rng(4);
    ol::ViewRecord view;
    view.descriptor = histogram(rng);
    std::size_t i = 0;
    for (auto _ : state) {
      benchmark::DoNotOptimize(memory_result->teach("c" + std::to_string(i++ % 10), {&view, 1}));
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace

BENCHMARK(BM_ask_instance)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ask_bayes)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_teach_instance)
    ->Arg(10)
    ->Arg(100)
    ->Arg(1000)
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(200);
BENCHMARK(BM_teach_memory_synced)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->Iterations(200);

BENCHMARK_MAIN();
