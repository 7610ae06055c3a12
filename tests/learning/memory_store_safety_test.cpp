// Opening a store never destroys or creates what it must not (issue 16, data loss 1 and 4): a store
// whose CURRENT is lost, a directory of other files and a LevelDB database of someone else are
// refused untouched; only OpenMode::CREATE creates, and only where nothing is; a read-only open
// refuses every write; an export into the store is refused.
#include <gtest/gtest.h>
#include <leveldb/db.h>

#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "memory_test_util.hpp"

namespace orthoflow::learning {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::make_view;
using test::small_config;
using Code = MemoryError::Code;
constexpr std::size_t LENGTH = 75;

/// Name -> bytes of every file in @p dir: what "untouched" compares.
std::map<std::string, std::string> contents(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::ifstream in(e.path(), std::ios::binary);
    out[e.path().filename().string()] = std::string(std::istreambuf_iterator<char>(in), {});
  }
  return out;
}

void make_store(const fs::path& dir) {
  auto m = PerceptualMemory::open(dir, small_config(), OpenMode::CREATE);
  ASSERT_TRUE(m) << m.error().to_string();
  ASSERT_TRUE(m->teach("mug", std::vector{make_view(LENGTH, 1, 1), make_view(LENGTH, 1, 2)}));
}

TEST(StoreSafety, AStoreWithoutCurrentIsRefusedUntouchedInEveryMode) {
  const auto dir = fresh_dir();
  make_store(dir);
  fs::remove(dir / "CURRENT");
  const auto before = contents(dir);
  for (const OpenMode mode : {OpenMode::READ_ONLY, OpenMode::READ_WRITE, OpenMode::CREATE}) {
    auto opened = PerceptualMemory::open(dir, small_config(), mode);
    ASSERT_FALSE(opened);
    EXPECT_EQ(opened.error().code, Code::CORRUPT);
    EXPECT_NE(opened.error().message.find("CURRENT"), std::string::npos) << opened.error().message;
  }
  EXPECT_EQ(contents(dir), before);
}

TEST(StoreSafety, ADirectoryOfOtherFilesIsRefusedUntouched) {
  const auto dir = fresh_dir();
  fs::create_directories(dir);
  std::ofstream(dir / "notes.txt") << "my thesis";
  auto opened = PerceptualMemory::open(dir, small_config(), OpenMode::CREATE);
  ASSERT_FALSE(opened);
  EXPECT_EQ(opened.error().code, Code::OPEN_FAILED);
  EXPECT_EQ(contents(dir), (std::map<std::string, std::string>{{"notes.txt", "my thesis"}}));
}

TEST(StoreSafety, SomeoneElsesLevelDbIsRefusedUntouched) {
  const auto dir = fresh_dir();
  {
    leveldb::Options options;
    options.create_if_missing = true;
    leveldb::DB* raw = nullptr;
    ASSERT_TRUE(leveldb::DB::Open(options, dir.string(), &raw).ok());
    std::unique_ptr<leveldb::DB> db(raw);
    ASSERT_TRUE(db->Put(leveldb::WriteOptions(), "theirs", "value").ok());
  }
  auto opened = PerceptualMemory::open(dir, small_config(), OpenMode::CREATE);
  ASSERT_FALSE(opened);
  EXPECT_EQ(opened.error().code, Code::OPEN_FAILED);
  EXPECT_NE(opened.error().message.find("schema"), std::string::npos) << opened.error().message;
  leveldb::DB* raw = nullptr;
  ASSERT_TRUE(leveldb::DB::Open(leveldb::Options(), dir.string(), &raw).ok());
  std::unique_ptr<leveldb::DB> db(raw);
  std::string value;
  EXPECT_TRUE(
      db->Get(leveldb::ReadOptions(), "s", &value).IsNotFound());  // no schema key was written
  EXPECT_TRUE(db->Get(leveldb::ReadOptions(), "theirs", &value).ok());
}

TEST(StoreSafety, OnlyCreateCreatesAndOnlyWhereNothingIs) {
  const auto dir = fresh_dir();
  for (const OpenMode mode : {OpenMode::READ_ONLY, OpenMode::READ_WRITE}) {
    auto opened = PerceptualMemory::open(dir, small_config(), mode);
    ASSERT_FALSE(opened);
    EXPECT_EQ(opened.error().code, Code::OPEN_FAILED);
    EXPECT_FALSE(fs::exists(dir));
  }
  fs::create_directories(dir);  // an empty directory may become a store too
  EXPECT_TRUE(PerceptualMemory::open(dir, small_config(), OpenMode::CREATE));
}

TEST(StoreSafety, AReadOnlyOpenRefusesEveryWrite) {
  const auto dir = fresh_dir();
  make_store(dir);
  auto m = PerceptualMemory::open(dir, small_config(), OpenMode::READ_ONLY);
  ASSERT_TRUE(m) << m.error().to_string();
  EXPECT_EQ(m->stats().views, 2U);
  EXPECT_EQ(m->teach("bowl", std::vector{make_view(LENGTH, 9, 3)}).error().code, Code::READ_ONLY);
  EXPECT_EQ(m->correct("bowl", make_view(LENGTH, 9, 3)).error().code, Code::READ_ONLY);
  EXPECT_EQ(m->forget("mug").error().code, Code::READ_ONLY);
  EXPECT_EQ(m->stats().categories, 1U);
}

TEST(StoreSafety, AnExportIntoTheStoreIsRefused) {
  const auto dir = fresh_dir();
  make_store(dir);
  auto m = PerceptualMemory::open(dir, small_config(), OpenMode::READ_ONLY);
  ASSERT_TRUE(m);
  for (const fs::path& target :
       {dir / "CURRENT", dir / "export.jsonl", dir / "." / "sub" / ".." / "CURRENT"}) {
    auto exported = m->export_to(target);
    ASSERT_FALSE(exported) << target;
    EXPECT_EQ(exported.error().code, Code::FILE_FAILED);
  }
  m = PerceptualMemory::open(fresh_dir("_other"), small_config(), OpenMode::CREATE);  // closes dir
  EXPECT_TRUE(PerceptualMemory::open(dir, small_config(), OpenMode::READ_ONLY));
}

}  // namespace
}  // namespace orthoflow::learning
