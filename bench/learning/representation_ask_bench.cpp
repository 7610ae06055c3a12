// ask() latency per representation at 10, 100 and 1000 categories of 10 views each (issue 22):
// the instance-based (plain nearest neighbour) and naive Bayes learners on GOOD (675 values), the
// bag of words (90 words) and LDA topics (30), and Local LDA on 90 words' counts with 30 topics per
// category (nearest view in chi-squared, and the topic models' likelihood). A view has 330 words,
// the spin images of a real bowl view (bench/RESULTS.md "bag of words"). Sets of spin images
// (approach I, D(T, O) to every view): 121 images of width 4 (45 values; the mean of synth26's
// views at VS 1 cm) and 40 of width 8 (153 values; a mug at the thesis's approach II VS 4 cm, SL 10
// cm).
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "learning/learner_choice.hpp"

namespace ok = orthoflow::kernels;
namespace ol = orthoflow::learning;

namespace {

constexpr std::size_t VIEWS_PER_CATEGORY = 10;
constexpr std::size_t WORDS = 90;
constexpr std::size_t TOPICS = 30;
constexpr int WORDS_PER_VIEW = 330;

// A dictionary of WORDS words (its values do not matter here: only its size and id are read).
std::shared_ptr<const ok::VisualDictionary> dictionary() {
  auto d = std::make_shared<ok::VisualDictionary>();
  d->words = WORDS;
  d->dims = ok::spin_image_bins(4);
  d->data.assign(d->words * d->dims, 0.5F);
  ok::TopicModel m;
  m.topics = TOPICS;
  m.words = WORDS;
  m.word_topic.assign(TOPICS * WORDS, 1);
  m.topic_total.assign(TOPICS, WORDS);
  d->topics = std::move(m);
  d->id = ok::dictionary_id(*d);
  return d;
}

// A view of category @p c: word counts drawn from the category's own 12 words (mostly) and any
// word; as shares (bag of words and topics) or counts (Local LDA).
std::vector<float> view(std::size_t length, std::size_t c, std::mt19937& rng, bool counts) {
  std::vector<float> v(length, 0.0F);
  std::uniform_int_distribution<std::size_t> any(0, length - 1), own(0, 11);
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  for (int i = 0; i < WORDS_PER_VIEW; ++i)
    v[u(rng) < 0.7F ? (c * 7 + own(rng)) % length : any(rng)] += 1.0F;
  if (!counts)
    for (float& x : v) x /= static_cast<float>(WORDS_PER_VIEW);
  return v;
}

// A set of @p images spin images around category @p c's own pattern.
std::vector<float> set_view(const ok::SpinSetParams& p, std::size_t images, std::size_t c,
                            std::mt19937& rng) {
  std::vector<float> v(p.length(), 0.0F);
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  v[0] = static_cast<float>(images);
  for (std::size_t i = 0; i < images * p.image_values(); ++i)
    v[1 + i] = 0.5F * u(rng) + (((i + c) % 7) == 0 ? 0.5F : 0.0F);
  return v;
}

void BM_ask(benchmark::State& state, ok::DescriptorSpec spec, ol::LearnerKind kind,
            std::size_t set_images = 0) {
  const bool counts = spec.kind == ok::DescriptorKind::LOCAL_LDA;
  const auto make = [&](std::size_t c, std::mt19937& rng) {
    return set_images > 0 ? set_view(spec.spin_set, set_images, c, rng)
                          : view(spec.length(), c, rng, counts);
  };
  ol::InstanceConfig instance;
  instance.normalise = false;
  auto learner = ol::make_learner(spec, kind, instance, ol::BayesConfig{});
  const std::size_t length = spec.length();
  const auto categories = static_cast<std::size_t>(state.range(0));
  std::mt19937 rng(6);
  for (std::size_t c = 0; c < categories; ++c) {
    std::vector<float> batch;
    for (std::size_t v = 0; v < VIEWS_PER_CATEGORY; ++v) {
      const auto x = make(c, rng);
      batch.insert(batch.end(), x.begin(), x.end());
    }
    if (!learner->teach("c" + std::to_string(c), ol::DescriptorBatch{batch, length})) {
      state.SkipWithError("teach refused");
      return;
    }
  }
  ol::AskScratch scratch;
  learner->prepare(scratch);
  const auto query = make(3, rng);
  for (auto _ : state) {
    const ol::Prediction p = learner->ask(query, scratch);
    benchmark::DoNotOptimize(p.score);
  }
  state.counters["categories"] = static_cast<double>(categories);
}

ok::DescriptorSpec good() { return ok::DescriptorSpec::make_good(15); }
ok::DescriptorSpec bow() { return ok::DescriptorSpec::make_bow(dictionary()); }
ok::DescriptorSpec lda() { return ok::DescriptorSpec::make_lda(dictionary()); }
ok::DescriptorSpec local_lda() { return ok::DescriptorSpec::make_local_lda(dictionary()); }
ok::DescriptorSpec spin_vs1() {
  ok::SpinSetParams p;
  p.features = ok::SpinFeatureParams{};  // the bag of words' IW 4, SL 5 cm, VS 1 cm
  return ok::DescriptorSpec::make_spin_set(p);
}
ok::DescriptorSpec spin_vs4() { return ok::DescriptorSpec::make_spin_set(); }  // the thesis's

}  // namespace

#define ORTHOFLOW_ASK_BENCH(name, spec, kind)                    \
  BENCHMARK_CAPTURE(BM_ask, name, spec(), ol::LearnerKind::kind) \
      ->Arg(10)                                                  \
      ->Arg(100)                                                 \
      ->Arg(1000)                                                \
      ->Unit(benchmark::kMicrosecond)

ORTHOFLOW_ASK_BENCH(instance_good, good, INSTANCE);
ORTHOFLOW_ASK_BENCH(bayes_good, good, BAYES);
ORTHOFLOW_ASK_BENCH(instance_bow, bow, INSTANCE);
ORTHOFLOW_ASK_BENCH(bayes_bow, bow, BAYES);
ORTHOFLOW_ASK_BENCH(instance_lda, lda, INSTANCE);
ORTHOFLOW_ASK_BENCH(bayes_lda, lda, BAYES);
ORTHOFLOW_ASK_BENCH(instance_local_lda, local_lda, INSTANCE);
ORTHOFLOW_ASK_BENCH(likelihood_local_lda, local_lda, BAYES);
BENCHMARK_CAPTURE(BM_ask, instance_spin_set_121x45, spin_vs1(), ol::LearnerKind::INSTANCE, 121)
    ->Arg(10)
    ->Arg(100)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ask, instance_spin_set_40x153, spin_vs4(), ol::LearnerKind::INSTANCE, 40)
    ->Arg(10)
    ->Arg(100)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
