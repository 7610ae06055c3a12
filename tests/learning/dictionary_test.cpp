// The dictionary builder (learning/dictionary.hpp): k-means finds planted clusters, is the same for
// a seed on 1 and 2 threads (and on x86 and ARM: a pinned id of the words, checked under qemu too),
// refuses bad pools with the reason; the dictionary file round-trips, and a truncated, altered or
// foreign file is refused with the reason.
#include "learning/dictionary.hpp"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "core/rng.hpp"
#include "kernels/descriptor_spec.hpp"

namespace ol = orthoflow::learning;
namespace ok = orthoflow::kernels;

namespace {

// @p per points around each of @p centres (dims values each), uniform noise of +-spread.
std::vector<float> blobs(const std::vector<std::vector<float>>& centres, std::size_t per,
                         float spread, std::uint64_t seed) {
  orthoflow::core::Rng rng(seed);
  std::vector<float> rows;
  for (std::size_t i = 0; i < per; ++i)
    for (const auto& c : centres)
      for (const float v : c) rows.push_back(v + static_cast<float>(rng.uniform(-spread, spread)));
  return rows;
}

// A pool like spin images: 45 non-negative values per row, seeded.
std::vector<float> image_pool(std::size_t rows, std::uint64_t seed) {
  orthoflow::core::Rng rng(seed);
  std::vector<float> pool(rows * 45);
  for (float& v : pool) v = static_cast<float>(rng.uniform() * rng.uniform());
  return pool;
}

ol::KMeansResult run_on_threads(std::span<const float> rows, std::size_t dims,
                                const ol::KMeansParams& params, int threads) {
  tbb::task_arena arena(threads);
  ol::KMeansResult out;
  arena.execute([&] {
    auto r = ol::kmeans(rows, dims, params);
    EXPECT_TRUE(r);
    out = std::move(r.value());
  });
  return out;
}

}  // namespace

TEST(KMeans, FindsPlantedClusters) {
  const std::vector<std::vector<float>> centres{{0, 0}, {10, 0}, {0, 10}, {10, 10}};
  const auto rows = blobs(centres, 50, 1.0F, 3);
  ol::KMeansParams params;
  params.k = 4;
  params.seed = 7;
  auto r = ol::kmeans(rows, 2, params);
  ASSERT_TRUE(r);
  for (const auto& c : centres) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < 4; ++j)
      best = std::min(best,
                      double(std::hypot(r->centres[2 * j] - c[0], r->centres[2 * j + 1] - c[1])));
    EXPECT_LT(best, 0.5) << c[0] << "," << c[1];
  }
  // Points of one blob share a centre, and the four blobs have four centres.
  for (std::size_t b = 0; b < 4; ++b)
    for (std::size_t i = 1; i < 50; ++i) EXPECT_EQ(r->assignment[i * 4 + b], r->assignment[b]);
  EXPECT_LT(r->inertia, 200.0 * 2.0 / 3.0 * 1.01);  // uniform +-1: variance 1/3 per value
  EXPECT_GE(r->iterations, 1U);
}

TEST(KMeans, TheSameForASeedOnOneAndTwoThreads) {
  const auto pool = image_pool(3000, 11);
  ol::KMeansParams params;
  params.k = 30;
  params.seed = 5;
  params.max_iterations = 20;
  const auto one = run_on_threads(pool, 45, params, 1);
  const auto two = run_on_threads(pool, 45, params, 2);
  EXPECT_EQ(one.centres, two.centres);
  EXPECT_EQ(one.assignment, two.assignment);
  EXPECT_EQ(one.iterations, two.iterations);
  EXPECT_EQ(one.inertia, two.inertia);
  params.seed = 6;
  EXPECT_NE(run_on_threads(pool, 45, params, 2).centres, one.centres);
}

// The words of a fixed pool and seed, hashed: the same bits on every machine. The value is what
// x86-64 computes; the aarch64 build runs this test under qemu against the same value.
TEST(KMeans, PinnedWordsAreTheSameOnEveryMachine) {
  const auto pool = image_pool(2000, 21);
  ok::SpinFeatureParams features;
  ol::KMeansParams params;
  params.k = 16;
  params.seed = 3;
  params.max_iterations = 15;
  auto d = ol::build_dictionary(pool, features, params, "pinned test pool");
  ASSERT_TRUE(d) << d.error();
  EXPECT_EQ(ok::dictionary_id_hex(d->id), "bcbcce9f64ebe411");
}

TEST(KMeans, RefusesBadPoolsWithTheReason) {
  ol::KMeansParams params;
  params.k = 3;
  const std::vector<float> two_rows{0, 0, 1, 1};
  auto r = ol::kmeans(two_rows, 2, params);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("2 rows cannot make 3 clusters"), std::string::npos) << r.error();
  params.k = 0;
  EXPECT_FALSE(ol::kmeans(two_rows, 2, params));
  params.k = 1;
  EXPECT_FALSE(ol::kmeans(two_rows, 3, params));  // not whole rows
  EXPECT_FALSE(ol::kmeans(two_rows, 0, params));
  const std::vector<float> nan_row{0, std::numeric_limits<float>::quiet_NaN()};
  r = ol::kmeans(nan_row, 2, params);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("row 0"), std::string::npos) << r.error();
}

TEST(KMeans, DuplicateRowsStillGiveKCentres) {
  std::vector<float> rows(20, 1.0F);  // ten equal rows of two values, and two others
  rows.insert(rows.end(), {5, 5, 9, 9});
  ol::KMeansParams params;
  params.k = 3;
  auto r = ol::kmeans(rows, 2, params);
  ASSERT_TRUE(r) << r.error();
  std::vector<float> xs{r->centres[0], r->centres[2], r->centres[4]};
  std::sort(xs.begin(), xs.end());
  EXPECT_EQ(xs, (std::vector<float>{1, 5, 9}));
}

TEST(Dictionary, BuildsWordsFromThePoolLeavingOutEmptyImages) {
  auto pool = image_pool(500, 4);
  std::fill_n(pool.begin(), 45 * 100, 0.0F);  // 100 images without weight
  ol::KMeansParams params;
  params.k = 10;
  auto d = ol::build_dictionary(pool, {}, params, "test");
  ASSERT_TRUE(d) << d.error();
  EXPECT_EQ(d->words, 10U);
  EXPECT_EQ(d->dims, 45U);
  EXPECT_EQ(d->data.size(), 450U);
  EXPECT_EQ(d->id, ok::dictionary_id(*d));
  EXPECT_NE(d->provenance.find("400 spin images"), std::string::npos) << d->provenance;
  EXPECT_TRUE(ok::DescriptorSpec::make_bow(std::make_shared<ok::VisualDictionary>(*d)).validate());
  ok::SpinFeatureParams wide;
  wide.spin.image_width = 8;  // 153 values per image: 45-value rows do not fit
  EXPECT_FALSE(ol::build_dictionary(pool, wide, params, "test"));
}

TEST(DictionaryFile, RoundTripsAndRefusesDamage) {
  ol::KMeansParams params;
  params.k = 8;
  auto d = ol::build_dictionary(image_pool(200, 8), {}, params, "round trip");
  ASSERT_TRUE(d);
  const std::string bytes = ol::encode_dictionary(*d);
  auto back = ol::parse_dictionary(bytes);
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(back->data, d->data);
  EXPECT_EQ(back->id, d->id);
  EXPECT_EQ(back->provenance, d->provenance);
  EXPECT_EQ(back->spin.support_length, d->spin.support_length);
  // Truncated anywhere: refused.
  for (std::size_t cut = 0; cut < bytes.size(); cut += 37) {
    EXPECT_FALSE(ol::parse_dictionary(std::span<const char>(bytes.data(), cut))) << cut;
  }
  // A changed word value: the id no longer matches, and the error says so.
  std::string altered = bytes;
  altered[altered.size() - 3] ^= 0x40;
  auto bad = ol::parse_dictionary(altered);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().find("corrupt"), std::string::npos) << bad.error();
  EXPECT_FALSE(ol::parse_dictionary(std::string("OFDC") + bytes.substr(4)));
  // Saved and loaded through a file.
  const auto path = std::filesystem::temp_directory_path() /
                    ("orthoflow_dictionary_test_" + std::to_string(::getpid()) + ".ofwd");
  ASSERT_EQ(ol::save_dictionary(*d, path), "");
  auto loaded = ol::load_dictionary(path);
  ASSERT_TRUE(loaded);
  EXPECT_EQ(loaded->id, d->id);
  std::filesystem::remove(path);
  auto missing = ol::load_dictionary(path);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().find(path.string()), std::string::npos);
}

// The fuzzer's seed (tests/fuzz/corpus/dictionary), written by hand from the format's description:
// the parser reads it, so the documented layout and the code agree.
TEST(DictionaryFile, ReadsTheHandWrittenFuzzSeed) {
  auto d = ol::load_dictionary(std::filesystem::path(ORTHOFLOW_SOURCE_DIR) /
                               "tests/fuzz/corpus/dictionary/two_words_iw1");
  ASSERT_TRUE(d) << d.error();
  EXPECT_EQ(d->words, 2U);
  EXPECT_EQ(d->dims, 6U);
  EXPECT_EQ(d->spin.image_width, 1U);
  EXPECT_EQ(d->provenance, "fuzz seed");
  EXPECT_EQ(d->data[1], 0.5F);
}

// The second seed has a topic model (file version 2), also written by hand.
TEST(DictionaryFile, ReadsTheHandWrittenFuzzSeedWithTopics) {
  auto d = ol::load_dictionary(std::filesystem::path(ORTHOFLOW_SOURCE_DIR) /
                               "tests/fuzz/corpus/dictionary/two_words_two_topics");
  ASSERT_TRUE(d) << d.error();
  ASSERT_TRUE(d->topics);
  EXPECT_EQ(d->topics->topics, 2U);
  EXPECT_EQ(d->topics->topic_total, (std::vector<std::uint32_t>{4, 2}));
  EXPECT_TRUE(d->topics->consistent());
}
