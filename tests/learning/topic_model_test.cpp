// The topic layer (kernels/topic_model.hpp, learning/topic_training.hpp): LDA recovers topics
// planted in documents generated from them; inference gives a document of one planted topic that
// topic; the counts stay consistent; refusals; the same counts and histograms for a seed (pinned:
// the aarch64 build runs this under qemu against the same value); the dictionary file keeps a topic
// model and its id covers it.
#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>
#include <numeric>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "core/rng.hpp"
#include "kernels/descriptor_spec.hpp"
#include "kernels/topic_model.hpp"
#include "learning/dictionary.hpp"
#include "learning/topic_training.hpp"

namespace ok = orthoflow::kernels;
namespace ol = orthoflow::learning;

namespace {

// Three planted topics over 12 words: topic t puts its weight on words 4t .. 4t + 3. Each document
// mixes two topics (a dominant one 80 %), 60 words.
std::vector<std::vector<std::uint32_t>> planted_documents(std::size_t count, std::uint64_t seed,
                                                          std::vector<int>* dominant = nullptr) {
  orthoflow::core::Rng rng(seed);
  std::vector<std::vector<std::uint32_t>> docs(count);
  for (std::size_t d = 0; d < count; ++d) {
    const auto main = static_cast<std::uint32_t>(rng.below(3));
    const auto other = static_cast<std::uint32_t>((main + 1 + rng.below(2)) % 3);
    if (dominant != nullptr) dominant->push_back(static_cast<int>(main));
    for (int i = 0; i < 60; ++i) {
      const std::uint32_t t = rng.uniform() < 0.8 ? main : other;
      docs[d].push_back(4 * t + static_cast<std::uint32_t>(rng.below(4)));
    }
  }
  return docs;
}

ol::TopicFitParams three_topics() {
  ol::TopicFitParams p;
  p.topics = 3;
  p.alpha = 0.5;
  p.beta = 0.1;
  p.iterations = 50;
  p.seed = 7;
  return p;
}

}  // namespace

TEST(Lda, RecoversPlantedTopics) {
  const auto docs = planted_documents(200, 1);
  auto m = ol::fit_lda(docs, 12, three_topics());
  ASSERT_TRUE(m) << m.error();
  EXPECT_TRUE(m->consistent());
  EXPECT_EQ(std::accumulate(m->topic_total.begin(), m->topic_total.end(), 0U), 200U * 60U);
  // Each fitted topic puts at least 90 % of its words on one planted topic's four words, and the
  // three fitted topics find three different planted ones.
  std::vector<int> found;
  for (std::size_t k = 0; k < 3; ++k) {
    int best = -1;
    for (int t = 0; t < 3; ++t) {
      std::uint32_t in = 0;
      for (int w = 4 * t; w < 4 * t + 4; ++w)
        in += m->word_topic[k * 12 + static_cast<std::size_t>(w)];
      if (in >= 0.9 * m->topic_total[k]) best = t;
    }
    ASSERT_GE(best, 0) << "fitted topic " << k << " mixes the planted ones";
    found.push_back(best);
  }
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, (std::vector<int>{0, 1, 2}));
}

TEST(Lda, InferenceGivesADocumentItsPlantedTopicAndLeavesTheModelAlone) {
  auto m = ol::fit_lda(planted_documents(200, 1), 12, three_topics());
  ASSERT_TRUE(m);
  const ok::TopicModel before = *m;
  std::vector<int> dominant;
  const auto tests = planted_documents(30, 99, &dominant);
  ok::TopicScratch scratch(3, 12, 60);
  std::size_t right = 0;
  std::vector<float> theta(3);
  // The fitted topic of each planted one: the topic holding most of its words.
  auto topic_of = [&](int t) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < 3; ++k)
      if (m->word_topic[k * 12 + static_cast<std::size_t>(4 * t)] >
          m->word_topic[best * 12 + static_cast<std::size_t>(4 * t)])
        best = k;
    return best;
  };
  for (std::size_t d = 0; d < tests.size(); ++d) {
    ASSERT_TRUE(ok::infer_topics(tests[d], *m, scratch, theta));
    EXPECT_NEAR(theta[0] + theta[1] + theta[2], 1.0F, 1e-5F);
    const auto top =
        static_cast<std::size_t>(std::max_element(theta.begin(), theta.end()) - theta.begin());
    right += top == topic_of(dominant[d]) ? 1 : 0;
  }
  EXPECT_GE(right, 28U);
  EXPECT_EQ(m->word_topic, before.word_topic);  // a temporary copy was sampled, not the model
  // The same document twice: the same histogram (its draws are seeded by its words).
  std::vector<float> again(3);
  ASSERT_TRUE(ok::infer_topics(tests[0], *m, scratch, again));
  ASSERT_TRUE(ok::infer_topics(tests[0], *m, scratch, theta));
  EXPECT_EQ(again, theta);
  // An empty document: the prior.
  ASSERT_TRUE(ok::infer_topics({}, *m, scratch, theta));
  EXPECT_FLOAT_EQ(theta[0], 1.0F / 3.0F);
  // Refusals: a word past the dictionary, a document longer than the scratch.
  const std::vector<std::uint32_t> bad{3, 12};
  EXPECT_FALSE(ok::infer_topics(bad, *m, scratch, theta));
  const std::vector<std::uint32_t> long_doc(61, 1);
  EXPECT_FALSE(ok::infer_topics(long_doc, *m, scratch, theta));
}

TEST(Lda, RefusesBadInput) {
  const auto docs = planted_documents(5, 2);
  auto p = three_topics();
  p.topics = 0;
  EXPECT_FALSE(ol::fit_lda(docs, 12, p));
  p = three_topics();
  p.alpha = 0.0;
  EXPECT_FALSE(ol::fit_lda(docs, 12, p));
  auto r = ol::fit_lda(docs, 8, three_topics());  // words 8..11 are past a dictionary of 8
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("past the dictionary"), std::string::npos) << r.error();
  EXPECT_FALSE(ol::fit_lda(std::vector<std::vector<std::uint32_t>>(3), 12, three_topics()));
}

// The fitted counts and one inferred histogram, hashed: the same on every machine (the value is
// x86-64's; the aarch64 build checks it under qemu).
TEST(Lda, PinnedCountsAndHistogramAreTheSameOnEveryMachine) {
  auto m = ol::fit_lda(planted_documents(100, 5), 12, three_topics());
  ASSERT_TRUE(m);
  ok::TopicScratch scratch(3, 12, 60);
  std::vector<float> theta(3);
  ASSERT_TRUE(ok::infer_topics(planted_documents(1, 6)[0], *m, scratch, theta));
  std::uint64_t h = 1469598103934665603ULL;
  for (const std::uint32_t n : m->word_topic) h = (h ^ n) * 1099511628211ULL;
  for (const float t : theta) h = (h ^ std::bit_cast<std::uint32_t>(t)) * 1099511628211ULL;
  EXPECT_EQ(ok::dictionary_id_hex(h), "c4ba5968cabf5121");
}

TEST(Lda, TheDictionaryFileKeepsItsTopicModel) {
  orthoflow::core::Rng rng(3);
  std::vector<std::vector<float>> views(6);
  for (auto& v : views) {
    v.resize(40 * 45);
    for (float& x : v) x = static_cast<float>(rng.uniform() * rng.uniform());
  }
  std::vector<float> pool;
  for (const auto& v : views) pool.insert(pool.end(), v.begin(), v.end());
  ol::KMeansParams km;
  km.k = 12;
  auto d = ol::build_dictionary(pool, {}, km, "topics test");
  ASSERT_TRUE(d);
  const std::uint64_t words_only = d->id;
  ol::TopicFitParams tp;
  tp.topics = 4;
  ASSERT_TRUE(ol::add_topics(*d, views, tp));
  ASSERT_TRUE(d->topics);
  EXPECT_NE(d->id, words_only);  // the id covers the topic model
  EXPECT_EQ(std::accumulate(d->topics->topic_total.begin(), d->topics->topic_total.end(), 0U),
            6U * 40U);
  const std::string bytes = ol::encode_dictionary(*d);
  auto back = ol::parse_dictionary(bytes);
  ASSERT_TRUE(back) << back.error();
  ASSERT_TRUE(back->topics);
  EXPECT_EQ(back->topics->word_topic, d->topics->word_topic);
  EXPECT_EQ(back->topics->topic_total, d->topics->topic_total);
  EXPECT_EQ(back->id, d->id);
  std::string altered = bytes;
  altered[altered.size() - 2] ^= 0x01;  // one topic count changed
  auto bad = ol::parse_dictionary(altered);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().find("corrupt"), std::string::npos) << bad.error();
  EXPECT_FALSE(ol::parse_dictionary(std::string_view(bytes).substr(0, bytes.size() - 4)));
  // The LDA specification: K values; a dictionary without topics is refused, with the remedy.
  auto dict = std::make_shared<const ok::VisualDictionary>(*back);
  const auto lda = ok::DescriptorSpec::make_lda(dict);
  EXPECT_EQ(lda.length(), 4U);
  EXPECT_TRUE(lda.validate());
  EXPECT_NE(lda.describe().find("lda topics=4 alpha=1 beta=0.1 iterations=30 words=12"),
            std::string::npos)
      << lda.describe();
  auto plain = std::make_shared<ok::VisualDictionary>(*back);
  plain->topics.reset();
  const auto refused = ok::DescriptorSpec::make_lda(plain).validate();
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("--topics"), std::string::npos) << refused.error();
}
