// The LevelDB perceptual memory: persistence across reopen, parameter checks, forget,
// export/import, and every MemoryError code.
#include <gtest/gtest.h>
#include <leveldb/db.h>
#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <fstream>

#include "memory_test_util.hpp"

namespace orthoflow::learning {
namespace {

using test::fresh_dir;
using test::make_view;
using test::small_config;
using Code = MemoryError::Code;
constexpr std::size_t LENGTH = 75;

PerceptualMemory must_open(const std::filesystem::path& dir, const MemoryConfig& cfg) {
  auto memory_result = PerceptualMemory::open(dir, cfg);
  if (!memory_result) { ADD_FAILURE() << memory_result.error().to_string(); }
  return std::move(memory_result).value();
}

void teach_three(PerceptualMemory& m) {
  ASSERT_EQ(*m.teach("mug", std::vector{make_view(LENGTH, 1, 1), make_view(LENGTH, 1, 2)}), 0U);
  ASSERT_EQ(*m.teach("bowl", std::vector{make_view(LENGTH, 9, 3), make_view(LENGTH, 9, 4)}), 1U);
  ASSERT_EQ(*m.correct("knife", make_view(LENGTH, 17, 5)), 2U);
}

TEST(PerceptualMemory, ReopenRestoresCategoriesViewsAndAnswers) {
  const auto dir = fresh_dir();
  AskScratch scratch;
  const ViewRecord query = make_view(LENGTH, 9, 11);
  for (const LearnerKind kind : {LearnerKind::INSTANCE, LearnerKind::BAYES}) {
    std::filesystem::remove_all(dir);
    Prediction before;
    {
      auto m = must_open(dir, small_config(kind));
      teach_three(m);
      before = m.learner().ask(query.descriptor, scratch);
      EXPECT_EQ(before.label.view(), "bowl");
      EXPECT_EQ(m.stats().writes, 3U);
    }
    auto m = must_open(dir, small_config(kind));
    const auto list = m.list();
    ASSERT_EQ(list.size(), 3U);
    EXPECT_EQ(list[0].label, "mug");
    EXPECT_EQ(list[1].views, 2U);
    EXPECT_EQ(list[2].label, "knife");
    EXPECT_EQ(m.stats().views, 5U);
    const Prediction after = m.learner().ask(query.descriptor, scratch);
    EXPECT_EQ(after.label, before.label);
    EXPECT_FLOAT_EQ(after.score, before.score);
    const auto views = m.views_of(1);
    ASSERT_TRUE(views);
    ASSERT_EQ(views->size(), 2U);
    EXPECT_EQ((*views)[1].track_id, 4U);
    EXPECT_EQ((*views)[1].descriptor, make_view(LENGTH, 9, 4).descriptor);
    EXPECT_EQ((*views)[1].frame, make_view(LENGTH, 9, 4).frame);
    EXPECT_EQ(*m.teach("cup", std::vector{make_view(LENGTH, 4, 6)}),
              3U);  // ids continue after reopen
  }
}

TEST(PerceptualMemory, EitherLearnerOpensTheSameStore) {
  const auto dir = fresh_dir();
  {
    auto m = must_open(dir, small_config(LearnerKind::INSTANCE));
    teach_three(m);
  }
  auto m = must_open(dir, small_config(LearnerKind::BAYES));
  EXPECT_STREQ(m.learner().kind(), "bayes");
  AskScratch scratch;
  EXPECT_EQ(m.learner().ask(make_view(LENGTH, 17, 8).descriptor, scratch).label.view(), "knife");
}

TEST(PerceptualMemory, OtherDescriptorParametersAreRejected) {
  const auto dir = fresh_dir();
  {
    auto m = must_open(dir, small_config());
    teach_three(m);
  }
  MemoryConfig other = small_config();
  other.descriptor.good.bins = 6;
  auto bins_result = PerceptualMemory::open(dir, other);
  ASSERT_FALSE(bins_result);
  EXPECT_EQ(bins_result.error().code, Code::PARAMS_MISMATCH);
  EXPECT_NE(bins_result.error().message.find("bins=5"), std::string::npos)
      << bins_result.error().message;
  EXPECT_NE(bins_result.error().message.find("bins=6"), std::string::npos);
  other = small_config();
  other.descriptor.good.mode = kernels::GoodMode::REFERENCE;
  EXPECT_EQ(PerceptualMemory::open(dir, other).error().code, Code::PARAMS_MISMATCH);
  other = small_config();
  other.descriptor.good.threshold = 0.02F;
  EXPECT_EQ(PerceptualMemory::open(dir, other).error().code, Code::PARAMS_MISMATCH);
  EXPECT_EQ(must_open(dir, small_config()).stats().views, 5U);  // untouched
}

TEST(PerceptualMemory, ForgetIsDurableAndUnknownLabelsAreReported) {
  const auto dir = fresh_dir();
  {
    auto m = must_open(dir, small_config());
    teach_three(m);
    ASSERT_TRUE(m.forget("bowl"));
    EXPECT_EQ(m.forget("bowl").error().code, Code::UNKNOWN_LABEL);
  }
  auto m = must_open(dir, small_config());
  ASSERT_EQ(m.list().size(), 2U);
  EXPECT_EQ(m.views_of(1)->size(), 0U);
  AskScratch scratch;
  EXPECT_NE(m.learner().ask(make_view(LENGTH, 9, 3).descriptor, scratch).label.view(), "bowl");
}

// Undo in the store: exactly the last lesson's views go, durably, for either learner; a lesson
// that is not the category's last is refused and nothing changes.
TEST(PerceptualMemory, RetractTakesBackTheLastLessonDurably) {
  const auto dir = fresh_dir();
  AskScratch scratch;
  const ViewRecord late = make_view(LENGTH, 1, 7);
  const ViewRecord query = make_view(LENGTH, 1, 12);
  for (const LearnerKind kind : {LearnerKind::INSTANCE, LearnerKind::BAYES}) {
    std::filesystem::remove_all(dir);
    Prediction never;
    {
      auto m = must_open(dir, small_config(kind));
      teach_three(m);
      never = m.learner().ask(query.descriptor, scratch);
      ASSERT_TRUE(m.teach("mug", std::vector{late}));
      EXPECT_EQ(m.stats().views, 6U);
      const ViewRecord first = make_view(LENGTH, 1, 1);  // the batch only views its floats
      const DescriptorBatch wrong{first.descriptor, LENGTH};
      const auto refused = m.retract("mug", wrong);  // mug's first view, not its last
      ASSERT_FALSE(refused);
      EXPECT_EQ(refused.error().code, Code::REJECTED);
      EXPECT_EQ(m.retract("cup", {late.descriptor, LENGTH}).error().code, Code::UNKNOWN_LABEL);
      EXPECT_EQ(m.stats().views, 6U);
      const auto retracted = m.retract("mug", {late.descriptor, LENGTH});
      ASSERT_TRUE(retracted) << retracted.error().to_string();
      EXPECT_EQ(m.stats().views, 5U);
    }
    auto m = must_open(dir, small_config(kind));  // what the undo left is what a reopen finds
    EXPECT_EQ(m.stats().views, 5U);
    ASSERT_EQ(m.list().size(), 3U);
    EXPECT_EQ(m.list()[0].views, 2U);
    ASSERT_EQ(m.views_of(0)->size(), 2U);
    EXPECT_EQ(m.views_of(0)->back().descriptor, make_view(LENGTH, 1, 2).descriptor);
    const Prediction after = m.learner().ask(query.descriptor, scratch);
    EXPECT_EQ(after.label, never.label);
    EXPECT_NEAR(after.score, never.score, 1e-5F * (1.0F + std::abs(never.score)));
    // Taking back a category's only lesson removes the category, in the store too.
    ASSERT_TRUE(m.retract("knife", {make_view(LENGTH, 17, 5).descriptor, LENGTH}));
    EXPECT_EQ(m.list().size(), 2U);
  }
  auto m = must_open(dir, small_config());
  EXPECT_EQ(m.list().size(), 2U);
  EXPECT_EQ(m.views_of(2)->size(), 0U);
}

TEST(PerceptualMemory, RejectedTeachWritesNothing) {
  const auto dir = fresh_dir();
  {
    auto m = must_open(dir, small_config());
    teach_three(m);
    ViewRecord short_view = make_view(LENGTH, 1, 1);
    short_view.descriptor.pop_back();
    const auto r = m.teach("mug", std::vector{make_view(LENGTH, 1, 9), short_view});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Code::REJECTED);
    EXPECT_NE(r.error().message.find("view 1"), std::string::npos) << r.error().message;
    EXPECT_EQ(m.teach(std::string(64, 'x'), std::vector{make_view(LENGTH, 1, 1)}).error().code,
              Code::REJECTED);
    EXPECT_EQ(m.teach("empty", std::vector<ViewRecord>{}).error().code, Code::REJECTED);
    ViewRecord negative = make_view(LENGTH, 1, 1);
    negative.descriptor[0] = -0.5F;
    EXPECT_EQ(m.correct("mug", negative).error().code, Code::REJECTED);
  }
  EXPECT_EQ(must_open(dir, small_config()).stats().views, 5U);
}

TEST(PerceptualMemory, ExportImportRoundTrip) {
  const auto dir = fresh_dir();
  const auto file = dir.string() + ".jsonl";
  auto m = must_open(dir, small_config());
  teach_three(m);
  ASSERT_EQ(*m.export_to(file), 5U);
  std::ifstream in(file);
  std::string header;
  std::getline(in, header);
  EXPECT_NE(header.find("\"schema\":1"), std::string::npos) << header;
  const auto copy_dir = fresh_dir("_copy");
  auto copy = must_open(copy_dir, small_config(LearnerKind::BAYES));
  ASSERT_EQ(*copy.import_from(file), 5U);
  const auto a = m.list();
  const auto b = copy.list();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].label, b[k].label);
    EXPECT_EQ(a[k].views, b[k].views);
  }
  EXPECT_EQ(copy.views_of(2)->at(0).stamp_ns, 5);
}

TEST(PerceptualMemory, BadImportsAndFilesAreReported) {
  const auto dir = fresh_dir();
  auto m = must_open(dir, small_config());
  EXPECT_EQ(m.export_to("/nonexistent_dir/x.jsonl").error().code, Code::FILE_FAILED);
  EXPECT_EQ(m.import_from("/nonexistent_dir/x.jsonl").error().code, Code::FILE_FAILED);
  const auto write = [&](const std::string& text) {
    const auto path = dir.string() + ".bad.jsonl";
    std::ofstream(path) << text;
    return path;
  };
  const std::string header = R"({"schema":1,"bins":5,"mode":"invariant","threshold":0.015})";
  EXPECT_EQ(m.import_from(write(R"({"schema":1,"bins":7,"mode":"invariant","threshold":0.015})"))
                .error()
                .code,
            Code::BAD_IMPORT);
  EXPECT_EQ(m.import_from(write(R"({"schema":9,"bins":5,"mode":"invariant","threshold":0.015})"))
                .error()
                .code,
            Code::BAD_IMPORT);
  const auto bad_line = m.import_from(write(header + "\n{\"label\":\"a\",\"descriptor\":[1,2]}\n"));
  ASSERT_FALSE(bad_line);
  EXPECT_EQ(bad_line.error().code, Code::BAD_IMPORT);
  EXPECT_NE(bad_line.error().message.find("line 2"), std::string::npos) << bad_line.error().message;
  EXPECT_EQ(m.import_from(write(header + "\nnot json\n")).error().code, Code::BAD_IMPORT);
  EXPECT_EQ(m.stats().categories, 0U);  // nothing imported from a bad file
}

TEST(PerceptualMemory, OpenFailuresAndCorruptRecords) {
  const auto dir = fresh_dir();
  auto first = must_open(dir, small_config());
  teach_three(first);
  auto locked =
      PerceptualMemory::open(dir, small_config());  // LevelDB's LOCK file: one opener at a time
  ASSERT_FALSE(locked);
  EXPECT_EQ(locked.error().code, Code::OPEN_FAILED);
  EXPECT_NE(locked.error().message.find(dir.string()), std::string::npos);
  first = must_open(fresh_dir("_other"), small_config());  // closes dir
  {
    leveldb::DB* raw = nullptr;
    ASSERT_TRUE(leveldb::DB::Open(leveldb::Options(), dir.string(), &raw).ok());
    std::unique_ptr<leveldb::DB> db(raw);
    const std::string key{'v', 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0};  // first view of category 1
    ASSERT_TRUE(db->Put(leveldb::WriteOptions(), key, "garbage").ok());
  }
  auto corrupt = PerceptualMemory::open(dir, small_config());
  ASSERT_FALSE(corrupt);
  EXPECT_EQ(corrupt.error().code, Code::CORRUPT);
  EXPECT_NE(corrupt.error().message.find("category 1 view 0"), std::string::npos)
      << corrupt.error().message;
}

TEST(PerceptualMemory, FailedSyncedWriteIsNotAcknowledged) {
  const auto dir = fresh_dir();
  auto m = must_open(dir, small_config());
  teach_three(m);
  // A file-size limit below the log's current size makes LevelDB's next append fail (EFBIG).
  rlimit saved{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit tiny = saved;
  tiny.rlim_cur = 1;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &tiny), 0);
  const auto r = m.teach("spoon", std::vector{make_view(LENGTH, 20, 7)});
  setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, old_handler);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, Code::WRITE_FAILED);
  EXPECT_EQ(m.learner().stats().categories, 3U);  // the learner never saw the unacknowledged teach
  EXPECT_EQ(m.list().size(), 3U);
}

TEST(PerceptualMemory, BadBinsIsAnOpenFailure) {
  MemoryConfig cfg = small_config();
  cfg.descriptor.good.bins = 0;
  EXPECT_EQ(PerceptualMemory::open(fresh_dir(), cfg).error().code, Code::OPEN_FAILED);
}

}  // namespace
}  // namespace orthoflow::learning
