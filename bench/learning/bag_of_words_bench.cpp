// The bag of words (docs/SPIN_IMAGES.md): one real object view (../shared/data/objects) described
// by GOOD and by the bag of words in the same run (keypoints, normals, spin images, words); the
// words of one view's spin images, exact SIMD vs the scalar twin; and k-means over a pool of spin
// images, seeding alone and seeding plus iterations (per iteration = the difference).
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "core/rng.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/descriptor_spec.hpp"
#include "kernels/point_normals.hpp"
#include "kernels/simd_arch.hpp"
#include "kernels/spin_features.hpp"
#include "kernels/topic_model.hpp"
#include "kernels/visual_words.hpp"
#include "learning/dictionary.hpp"
#include "learning/topic_training.hpp"

namespace ok = orthoflow::kernels;
namespace ol = orthoflow::learning;

namespace {

ok::PointCloud view(const char* name) {
  auto cloud = orthoflow::formats::read_pcd(std::string(ORTHOFLOW_SHARED_DIR) + "/data/objects/" +
                                            name + ".pcd");
  if (!cloud) std::abort();
  return std::move(cloud.value());
}

std::vector<float> random_pool(std::size_t rows, std::size_t dims) {
  orthoflow::core::Rng rng(3);
  std::vector<float> pool(rows * dims);
  for (float& v : pool) v = static_cast<float>(rng.uniform() * rng.uniform() * 0.2);
  return pool;
}

/// A dictionary of @p words drawn from the view's own spin images (every few images).
std::shared_ptr<const ok::VisualDictionary> words_of(const ok::PointCloud& cloud,
                                                     std::size_t words) {
  ok::SpinFeatures f;
  if (!f.compute(cloud.points(), {})) std::abort();
  const auto images = f.images();
  const std::size_t dims = ok::spin_image_bins(4), n = images.size() / dims;
  auto d = std::make_shared<ok::VisualDictionary>();
  d->words = words;
  d->dims = dims;
  d->data.resize(words * dims);
  for (std::size_t j = 0; j < words; ++j)
    for (std::size_t v = 0; v < dims; ++v)
      d->data[v * words + j] = images[(j * n / words) * dims + v];
  d->id = ok::dictionary_id(*d);
  return d;
}

/// A topic model of 30 topics over the words, fitted on 40 random documents of 300 words.
std::shared_ptr<const ok::VisualDictionary> with_topics(
    std::shared_ptr<const ok::VisualDictionary> words) {
  auto d = std::make_shared<ok::VisualDictionary>(*words);
  orthoflow::core::Rng rng(9);
  std::vector<std::vector<std::uint32_t>> docs(40);
  for (auto& doc : docs)
    for (int i = 0; i < 300; ++i) doc.push_back(static_cast<std::uint32_t>(rng.below(d->words)));
  auto m = ol::fit_lda(docs, d->words, {});
  if (!m) std::abort();
  d->topics = std::move(m.value());
  d->id = ok::dictionary_id(*d);
  return d;
}

void BM_Describe(benchmark::State& state, const char* name, int kind) {
  const ok::PointCloud cloud = view(name);
  const bool bow = kind > 0;
  const ok::DescriptorSpec spec =
      kind == 2   ? ok::DescriptorSpec::make_lda(with_topics(words_of(cloud, 90)))
      : kind == 1 ? ok::DescriptorSpec::make_bow(words_of(cloud, 70))
                  : ok::DescriptorSpec::make_good(15);
  ok::Describer describer(spec);
  std::vector<float> out(spec.length());
  for (auto _ : state) benchmark::DoNotOptimize(describer.describe(cloud.points(), out));
  state.counters["points"] = static_cast<double>(cloud.size());
  if (bow) state.counters["spin_images"] = static_cast<double>(describer.features());
}

template <bool SIMD>
void BM_WordsOfAView(benchmark::State& state) {
  const auto features = static_cast<std::size_t>(state.range(0));
  const auto words = static_cast<std::size_t>(state.range(1));
  const std::size_t dims = ok::spin_image_bins(4);
  const auto pool = random_pool(features, dims);
  const auto w = random_pool(words, dims);
  const ok::DescriptorMatrixView view{w, dims, words, words};
  std::vector<float> scratch(words);
  for (auto _ : state) {
    std::size_t sum = 0;
    for (std::size_t i = 0; i < features; ++i) {
      const std::span<const float> f(pool.data() + i * dims, dims);
      sum += SIMD ? ok::nearest_word(f, view, scratch) : ok::nearest_word_scalar(f, view);
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(features));
  if (SIMD) state.SetLabel(ok::simd_arch_name());
}

// kernels::point_normals at the keypoints of one real view (VS 1 cm, radius 2 cm): the normals
// the bag of words spins its images about.
void BM_PointNormals(benchmark::State& state) {
  const ok::PointCloud cloud = view("bowl");
  const std::size_t n = cloud.size();
  ok::VoxelGridScratch voxels(n);
  std::vector<float> cx(n), cy(n), cz(n), nx(n), ny(n), nz(n);
  std::vector<std::uint32_t> keys(n);
  auto k = ok::voxel_keypoints(cloud.points(), 0.01F, voxels, {cx, cy, cz}, keys);
  if (!k) std::abort();
  keys.resize(k.value());
  for (auto _ : state)
    benchmark::DoNotOptimize(ok::point_normals(cloud.points(), keys, {}, {nx, ny, nz}));
  state.counters["keypoints"] = static_cast<double>(keys.size());
}

// Gibbs inference of one view's topics (30 topics, 90 words, 30 sweeps): sweeps per second.
void BM_TopicInference(benchmark::State& state) {
  const auto words = static_cast<std::size_t>(state.range(0));
  auto d = with_topics(std::make_shared<ok::VisualDictionary>([] {
    ok::VisualDictionary v;
    v.words = 90;
    return v;
  }()));
  orthoflow::core::Rng rng(2);
  std::vector<std::uint32_t> doc(words);
  for (auto& w : doc) w = static_cast<std::uint32_t>(rng.below(90));
  ok::TopicScratch scratch(30, 90, words);
  std::vector<float> theta(30);
  for (auto _ : state) benchmark::DoNotOptimize(ok::infer_topics(doc, *d->topics, scratch, theta));
  state.counters["sweeps_per_s"] = benchmark::Counter(
      30.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_KMeans(benchmark::State& state) {
  const auto rows = static_cast<std::size_t>(state.range(0));
  const auto pool = random_pool(rows, ok::spin_image_bins(4));
  ol::KMeansParams params;
  params.k = 70;
  params.max_iterations = static_cast<std::uint32_t>(state.range(1));
  for (auto _ : state) benchmark::DoNotOptimize(ol::kmeans(pool, ok::spin_image_bins(4), params));
}

}  // namespace

BENCHMARK_CAPTURE(BM_Describe, good_bowl, "bowl", 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Describe, bow_bowl, "bowl", 1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Describe, lda_bowl, "bowl", 2)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Describe, good_bottle, "bottle", 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Describe, bow_bottle, "bottle", 1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Describe, lda_bottle, "bottle", 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointNormals)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TopicInference)->Arg(331)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WordsOfAView<false>)
    ->Name("BM_WordsOfAView/scalar")
    ->Args({271, 70})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WordsOfAView<true>)
    ->Name("BM_WordsOfAView/simd")
    ->Args({271, 70})
    ->Unit(benchmark::kMicrosecond);
// 32,000 spin images: the thesis's pool (194 objects); 0 iterations = k-means++ seeding alone.
BENCHMARK(BM_KMeans)->Args({32000, 0})->Args({32000, 5})->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
