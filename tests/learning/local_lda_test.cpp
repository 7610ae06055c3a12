// Local LDA (learning/local_lda_learner.hpp): word counts expanded exactly; categories made of
// planted topics are told apart by every decision rule; the same teaching gives the same bits
// (one view at a time or in a batch, and replayed by restore()); retract takes a teach back;
// every refusal; a pinned value that the aarch64 build checks under qemu; and a memory store of
// word counts reopens with the same answers and refuses other topics, naming both.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/rng.hpp"
#include "kernels/visual_words.hpp"
#include "learning/detail/memory_codec.hpp"
#include "learning/local_lda_learner.hpp"
#include "learning/perceptual_memory.hpp"
#include "tests/learning/memory_test_util.hpp"

namespace orthoflow::learning {
namespace {

constexpr std::size_t WORDS = 12;

// Three planted topics over 12 words (topic t: words 4t .. 4t + 3). Category c draws 60 words,
// 75 % from its main topic (c % 3) and the rest from the topic after it, as word counts.
std::vector<float> planted_view(std::size_t category, std::uint64_t seed) {
  core::Rng rng(seed * 7919 + category);
  std::vector<float> counts(WORDS, 0.0F);
  const std::size_t main = category % 3, other = (category + 1) % 3;
  for (int i = 0; i < 60; ++i) {
    const std::size_t t = rng.uniform() < 0.75 ? main : other;
    counts[4 * t + rng.below(4)] += 1.0F;
  }
  return counts;
}

std::vector<float> planted_views(std::size_t category, std::size_t count, std::uint64_t first) {
  std::vector<float> out;
  for (std::size_t v = 0; v < count; ++v) {
    const auto view = planted_view(category, first + v);
    out.insert(out.end(), view.begin(), view.end());
  }
  return out;
}

LocalLdaConfig small(LocalLdaDecision decision = LocalLdaDecision::NEAREST) {
  LocalLdaConfig cfg;
  cfg.words = WORDS;
  cfg.topics.topics = 4;
  cfg.max_words = 256;
  cfg.decision = decision;
  return cfg;
}

void teach_three(Learner& learner, std::size_t views = 8) {
  for (std::size_t c = 0; c < 3; ++c)
    ASSERT_TRUE(learner.teach("c" + std::to_string(c), {planted_views(c, views, 1), WORDS}));
}

TEST(LocalLda, ExpandsWordCountsInIdOrder) {
  std::vector<std::uint32_t> out(8);
  const std::vector<float> counts{2, 0, 1, 0};
  ASSERT_EQ(expand_word_counts(counts, out), 3U);
  EXPECT_EQ((std::vector<std::uint32_t>(out.begin(), out.begin() + 3)),
            (std::vector<std::uint32_t>{0, 0, 2}));
  const float nan = std::nanf("");
  for (const std::vector<float>& bad :
       {std::vector<float>{1.5F, 0}, {-1, 2}, {nan, 1}, {INFINITY, 0}, {0, 0}, {5, 4}}) {
    EXPECT_FALSE(expand_word_counts(bad, out)) << bad[0] << " " << bad[1];
  }
  EXPECT_EQ(expand_word_counts(std::vector<float>{4, 4}, out), 8U);  // exactly full
}

TEST(LocalLda, EveryDecisionTellsPlantedCategoriesApart) {
  for (const LocalLdaDecision d :
       {LocalLdaDecision::NEAREST, LocalLdaDecision::NOCD_1, LocalLdaDecision::NOCD_2,
        LocalLdaDecision::LIKELIHOOD, LocalLdaDecision::TOPIC_HISTOGRAM}) {
    LocalLdaLearner learner(small(d));
    teach_three(learner);
    AskScratch scratch;
    learner.prepare(scratch);
    int right = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      for (std::uint64_t s = 100; s < 110; ++s) {
        const Prediction p = learner.ask(planted_view(c, s), scratch);
        right += !p.unknown && p.label.view() == "c" + std::to_string(c) ? 1 : 0;
      }
    }
    // Chance is 10 of 30. Naive Bayes over histograms of each category's own topics compares
    // incomparable scores (the file comment of local_lda_learner.hpp): it only has to beat chance.
    EXPECT_GE(right, d == LocalLdaDecision::TOPIC_HISTOGRAM ? 20 : 28)
        << learner.kind() << " decision " << static_cast<int>(d);
  }
}

TEST(LocalLda, TheSameTeachingGivesTheSameBitsOneByOneInABatchAndRestored) {
  LocalLdaLearner batch(small()), single(small()), restored(small());
  teach_three(batch);
  for (std::size_t c = 0; c < 3; ++c)
    for (std::uint64_t v = 1; v <= 8; ++v)
      ASSERT_TRUE(single.teach("c" + std::to_string(c), {planted_view(c, v), WORDS}));
  std::vector<std::vector<float>> stored;
  for (std::size_t c = 0; c < 3; ++c) stored.push_back(planted_views(c, 8, 1));
  const std::string labels[] = {"c0", "c1", "c2"};
  std::vector<RestoredCategory> categories;
  for (std::uint32_t c = 0; c < 3; ++c)
    categories.push_back(RestoredCategory{c, labels[c], {stored[c], WORDS}, {}, 0});
  ASSERT_TRUE(restored.restore(categories, 3));
  AskScratch a, b, r;
  batch.prepare(a);
  single.prepare(b);
  restored.prepare(r);
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_EQ(batch.view_topics(labels[c]), single.view_topics(labels[c]));
    EXPECT_EQ(batch.view_topics(labels[c]), restored.view_topics(labels[c]));
    const auto q = planted_view(c, 500);
    const Prediction pa = batch.ask(q, a), pb = single.ask(q, b), pr = restored.ask(q, r);
    EXPECT_EQ(std::bit_cast<std::uint32_t>(pa.score), std::bit_cast<std::uint32_t>(pb.score));
    EXPECT_EQ(std::bit_cast<std::uint32_t>(pa.score), std::bit_cast<std::uint32_t>(pr.score));
    EXPECT_EQ(pa.label, pr.label);
  }
  EXPECT_EQ(batch.stats().views, 24U);
  EXPECT_EQ(restored.stats().categories, 3U);
}

TEST(LocalLda, RetractTakesTheLastTeachBack) {
  LocalLdaLearner learner(small()), reference(small());
  const auto first = planted_views(0, 4, 1), late = planted_views(0, 2, 50);
  ASSERT_TRUE(learner.teach("mug", {first, WORDS}));
  ASSERT_TRUE(reference.teach("mug", {first, WORDS}));
  ASSERT_TRUE(learner.teach("mug", {late, WORDS}));
  EXPECT_EQ(learner.retract("mug", {first, WORDS}).error(), LearnError::NOT_LAST_VIEWS);
  EXPECT_EQ(learner.retract("cup", {late, WORDS}).error(), LearnError::UNKNOWN_LABEL);
  ASSERT_TRUE(learner.retract("mug", {late, WORDS}));
  EXPECT_EQ(learner.view_topics("mug"), reference.view_topics("mug"));  // the counts are back
  EXPECT_EQ(learner.stats().views, 4U);
  ASSERT_TRUE(learner.retract("mug", {first, WORDS}));
  EXPECT_EQ(learner.stats().categories, 0U);
}

TEST(LocalLda, RefusesWhatIsNotWordCounts) {
  LocalLdaLearner learner(small());
  auto view = planted_view(0, 1);
  view[3] = 0.5F;
  EXPECT_EQ(learner.teach("mug", {view, WORDS}).error(), LearnError::NOT_WORD_COUNTS);
  std::vector<float> too_many(WORDS, 0.0F);
  too_many[0] = 257.0F;
  EXPECT_EQ(learner.teach("mug", {too_many, WORDS}).error(), LearnError::NOT_WORD_COUNTS);
  EXPECT_EQ(learner.teach("mug", {std::vector<float>(WORDS, 0.0F), WORDS}).error(),
            LearnError::NOT_WORD_COUNTS);
  view[3] = -1.0F;
  EXPECT_EQ(learner.teach("mug", {view, WORDS}).error(), LearnError::NEGATIVE_VALUE);
  EXPECT_EQ(learner.teach("mug", {std::vector<float>(5, 1.0F), 5}).error(),
            LearnError::WRONG_LENGTH);
  const std::vector<float> none;
  const RestoredCategory without_views{0, "mug", {none, WORDS}, {}, 0};
  EXPECT_EQ(learner.restore(std::span(&without_views, 1), 1).error(), LearnError::NO_VIEWS);
  EXPECT_EQ(learner.stats().categories, 0U);  // nothing changed

  teach_three(learner, 3);
  AskScratch unprepared;
  EXPECT_TRUE(learner.ask(planted_view(0, 9), unprepared).unknown);
  EXPECT_TRUE(std::isnan(learner.ask(planted_view(0, 9), unprepared).score));
  AskScratch scratch;
  learner.prepare(scratch);
  EXPECT_FALSE(learner.ask(planted_view(0, 9), scratch).unknown);
  auto shares = planted_view(0, 9);
  for (float& x : shares) x /= 60.0F;  // a bag of words, not counts
  EXPECT_TRUE(learner.ask(shares, scratch).unknown);
}

// The topics of a taught category and one target's chi-squared distance, hashed: the same on
// every machine (the value is x86-64's; the aarch64 build checks it under qemu).
TEST(LocalLda, PinnedTopicsAndDistanceAreTheSameOnEveryMachine) {
  LocalLdaLearner learner(small());
  teach_three(learner);
  AskScratch scratch;
  learner.prepare(scratch);
  std::uint64_t h = 1469598103934665603ULL;
  for (const char* label : {"c0", "c1", "c2"})
    for (const float t : learner.view_topics(label))
      h = (h ^ std::bit_cast<std::uint32_t>(t)) * 1099511628211ULL;
  h = (h ^ std::bit_cast<std::uint32_t>(learner.ask(planted_view(1, 77), scratch).score)) *
      1099511628211ULL;
  EXPECT_EQ(kernels::dictionary_id_hex(h), "8001d046a1512361");
}

// A store of word counts: reopened, it answers as before (its learner replays the views); other
// topics are refused, naming both.
TEST(LocalLda, AStoreOfWordCountsReopensWithTheSameAnswers) {
  const auto dir = test::fresh_dir();
  MemoryConfig cfg = test::small_config(LearnerKind::BAYES);
  kernels::LocalTopics topics;
  topics.topics = 4;
  cfg.descriptor = kernels::DescriptorSpec::make_local_lda(test::test_dictionary(WORDS), topics);
  cfg.descriptor.good.bins = 5;
  const auto q = planted_view(2, 300);
  Prediction before;
  {
    auto m = PerceptualMemory::open(dir, cfg);
    ASSERT_TRUE(m) << m.error().to_string();
    for (std::size_t c = 0; c < 3; ++c) {
      std::vector<ViewRecord> views;
      for (std::uint64_t v = 1; v <= 5; ++v)
        views.push_back(ViewRecord{planted_view(c, v), {}, {}, 0, 0});
      ASSERT_TRUE(m->teach("c" + std::to_string(c), views));
    }
    AskScratch scratch;
    m->learner().prepare(scratch);
    before = m->learner().ask(q, scratch);
    EXPECT_EQ(before.label.view(), "c2");
    EXPECT_STREQ(m->learner().kind(), "local-lda-likelihood");
  }
  {
    auto again = PerceptualMemory::open(dir, cfg);
    ASSERT_TRUE(again) << again.error().to_string();
    AskScratch scratch;
    again->learner().prepare(scratch);
    const Prediction after = again->learner().ask(q, scratch);
    EXPECT_EQ(after.label, before.label);
    EXPECT_EQ(std::bit_cast<std::uint32_t>(after.score),
              std::bit_cast<std::uint32_t>(before.score));
  }
  MemoryConfig other = cfg;
  other.descriptor.local_topics.topics = 5;
  auto refused = PerceptualMemory::open(dir, other);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, MemoryError::Code::PARAMS_MISMATCH);
  EXPECT_NE(refused.error().to_string().find("topics=4"), std::string::npos)
      << refused.error().to_string();
  EXPECT_NE(refused.error().to_string().find("topics=5"), std::string::npos);
}

// The schema a store keeps names its topics, and a schema with topics the learner would refuse (a
// corrupt store) is refused when read, never handed to the learner (fuzz_memory_schema found
// numbers that do not fit a float).
TEST(LocalLda, TheStoredSchemaCarriesTheTopicsAndRefusesImpossibleOnes) {
  kernels::LocalTopics topics;
  topics.topics = 7;
  topics.seed = 99;
  const auto spec = kernels::DescriptorSpec::make_local_lda(test::test_dictionary(WORDS), topics);
  const std::string json = encode_schema(spec);
  std::uint32_t version = 0;
  std::string why;
  const auto back = decode_schema(json, version, why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(*back, spec);
  EXPECT_EQ(back->local_topics.topics, 7U);
  EXPECT_EQ(back->local_topics.seed, 99U);
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string bad = json;
    bad.replace(bad.find(from), from.size(), to);
    return decode_schema(bad, version, why);
  };
  EXPECT_FALSE(replaced("\"topics\":7", "\"topics\":0")) << "no topics";
  EXPECT_FALSE(replaced("\"alpha\":1.0", "\"alpha\":-1.0")) << "negative alpha";
  EXPECT_FALSE(replaced("\"iterations\":30", "\"iterations\":4294967296")) << "too many sweeps";
  EXPECT_FALSE(replaced("\"support_angle_cos\":0.0", "\"support_angle_cos\":1e300"));
  EXPECT_NE(why.find("support_angle_cos"), std::string::npos) << why;
  EXPECT_FALSE(replaced("\"local_topics\"", "\"other_topics\""));
  EXPECT_FALSE(replaced("\"bins\":15", "\"bins\":100000")) << "bins past GOOD's limit";
}

}  // namespace
}  // namespace orthoflow::learning
