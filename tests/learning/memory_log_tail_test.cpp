// A damaged write-ahead-log tail is reported, not swallowed (issue 16, data loss 5): LevelDB drops
// a record cut short at the end of its log without a word, so the memory checks the tail itself.
// Every cut inside the last batch (one record, and one split over two 32 KiB blocks) is reported by
// a read-only open, which leaves the store as it was (the next open reports it again), and by a
// writable open; an intact log, zero padding and a cut at a batch boundary are not damage.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "learning/detail/log_tail.hpp"
#include "memory_test_util.hpp"

namespace orthoflow::learning {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::make_view;
using test::small_config;
constexpr std::size_t LENGTH = 75;

fs::path log_of(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".log") return e.path();
  }
  ADD_FAILURE() << "no log in " << dir;
  return {};
}

// A store with two small teaches and then @p last_views views under "last", closed; returns the
// log's size before the last teach.
std::uintmax_t make_store(const fs::path& dir, std::size_t last_views) {
  auto m = PerceptualMemory::open(dir, small_config(), OpenMode::CREATE);
  EXPECT_TRUE(m);
  EXPECT_TRUE(m->teach("mug", std::vector{make_view(LENGTH, 1, 1)}));
  EXPECT_TRUE(m->teach("bowl", std::vector{make_view(LENGTH, 4, 2)}));
  const std::uintmax_t before = fs::file_size(log_of(dir));
  std::vector<ViewRecord> views;
  for (std::size_t v = 0; v < last_views; ++v) views.push_back(make_view(LENGTH, 7, 10 + v));
  EXPECT_TRUE(m->teach("last", views));
  return before;
}

std::vector<std::string> labels(const PerceptualMemory& m) {
  std::vector<std::string> out;
  for (const auto& c : m.list()) out.push_back(c.label);
  return out;
}

TEST(LogTail, AnIntactLogIsNotDamage) {
  const auto dir = fresh_dir();
  make_store(dir, 1);
  EXPECT_FALSE(check_store_log(dir));
  auto m = PerceptualMemory::open(dir, small_config(), OpenMode::READ_ONLY);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->open_warnings().empty());
  EXPECT_EQ(labels(*m), (std::vector<std::string>{"mug", "bowl", "last"}));
}

TEST(LogTail, EveryCutInsideTheLastBatchIsReported) {
  // 1 view: one FULL record; 120 views: a batch of more than 32 KiB, FIRST .. LAST over blocks.
  for (const std::size_t views : {std::size_t{1}, std::size_t{120}}) {
    const auto source = fresh_dir("_source" + std::to_string(views));
    const std::uintmax_t before = make_store(source, views);
    const std::uintmax_t size = fs::file_size(log_of(source));
    ASSERT_GT(size, before);
    if (views > 1) { ASSERT_GT(size - before, 32768U); }
    const std::uintmax_t step = std::max<std::uintmax_t>(1, (size - before) / 40);
    for (std::uintmax_t cut = before + 1; cut < size; cut += step) {
      const std::string what = std::to_string(views) + " views, cut at " + std::to_string(cut);
      const auto dir = fresh_dir("_cut");
      fs::copy(source, dir);
      fs::resize_file(log_of(dir), cut);
      const auto damage = check_store_log(dir);
      ASSERT_TRUE(damage) << what;
      EXPECT_EQ(damage->dropped_bytes, cut - before) << what;
      for (int twice = 0; twice < 2; ++twice) {  // read-only: reported again, store untouched
        auto m = PerceptualMemory::open(dir, small_config(), OpenMode::READ_ONLY);
        ASSERT_TRUE(m) << what;
        ASSERT_EQ(m->open_warnings().size(), 1U) << what;
        EXPECT_NE(m->open_warnings()[0].find("acknowledged"), std::string::npos);
        EXPECT_EQ(labels(*m), (std::vector<std::string>{"mug", "bowl"})) << what;
        EXPECT_EQ(fs::file_size(log_of(dir)), cut) << what;
      }
      auto w = PerceptualMemory::open(dir, small_config(), OpenMode::READ_WRITE);
      ASSERT_TRUE(w) << what;
      EXPECT_EQ(w->open_warnings().size(), 1U) << what;
    }
  }
}

TEST(LogTail, ZeroPaddingAndACutAtABatchBoundaryAreNotDamage) {
  const auto dir = fresh_dir();
  const std::uintmax_t before = make_store(dir, 1);
  const fs::path log = log_of(dir);
  const std::uintmax_t size = fs::file_size(log);
  fs::resize_file(log, size + 100);  // zeros, as a preallocating file system leaves them
  EXPECT_FALSE(check_store_log(dir));
  // A cut exactly at the boundary leaves a whole log: indistinguishable from a store that never
  // took the last teach (RELIABILITY.md states this limit).
  fs::resize_file(log, before);
  EXPECT_FALSE(check_store_log(dir));
  auto m = PerceptualMemory::open(dir, small_config(), OpenMode::READ_ONLY);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->open_warnings().empty());
  EXPECT_EQ(labels(*m), (std::vector<std::string>{"mug", "bowl"}));
}

TEST(LogTail, GarbageAfterTheLastRecordIsReported) {
  const auto dir = fresh_dir();
  make_store(dir, 1);
  const fs::path log = log_of(dir);
  const std::uintmax_t size = fs::file_size(log);
  {
    std::FILE* f = std::fopen(log.c_str(), "ab");
    ASSERT_NE(f, nullptr);
    const unsigned char junk[] = {0x12, 0x34, 0x56, 0x78, 0xFF, 0xFF, 9, 1, 2, 3};
    std::fwrite(junk, 1, sizeof junk, f);
    std::fclose(f);
  }
  const auto damage = check_log_tail(log);
  ASSERT_TRUE(damage);
  EXPECT_EQ(damage->dropped_bytes, 10U);
  EXPECT_NE(damage->reason.find("not valid"), std::string::npos) << damage->reason;
  EXPECT_EQ(fs::file_size(log), size + 10);
}

}  // namespace
}  // namespace orthoflow::learning
