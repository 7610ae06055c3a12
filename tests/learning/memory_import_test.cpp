// Imports are all or nothing (issue 16, data loss 3): a truncated export (fewer views than its
// header says) imports nothing, the same export twice is refused the second time, and an import
// adds every category in one synced write (the store's writes counter moves by one).
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "memory_test_util.hpp"

namespace orthoflow::learning {
namespace {

using test::fresh_dir;
using test::make_view;
using test::small_config;
using Code = MemoryError::Code;
constexpr std::size_t LENGTH = 75;

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string exported(const std::string& tag) {
  auto m = PerceptualMemory::open(fresh_dir(tag), small_config(), OpenMode::CREATE);
  EXPECT_TRUE(m);
  for (std::size_t c = 0; c < 6; ++c) {
    EXPECT_TRUE(m->teach("cat" + std::to_string(c), std::vector{make_view(LENGTH, c * 3, c),
                                                                make_view(LENGTH, c * 3, c + 10)}));
  }
  const std::string file = fresh_dir(tag).string() + ".jsonl";
  EXPECT_EQ(*m->export_to(file), 12U);
  return file;
}

TEST(MemoryImport, OneSyncedWriteForTheWholeFile) {
  const std::string file = exported("_src");
  auto m = PerceptualMemory::open(fresh_dir(), small_config(), OpenMode::CREATE);
  ASSERT_TRUE(m);
  const auto writes = m->stats().writes;
  ASSERT_EQ(*m->import_from(file), 12U);
  EXPECT_EQ(m->stats().writes, writes + 1);
  EXPECT_EQ(m->stats().categories, 6U);
}

TEST(MemoryImport, ATruncatedExportImportsNothing) {
  const std::string file = exported("_src");
  const auto lines = lines_of(file);
  const std::string cut = file + ".cut";
  {
    std::ofstream out(cut);
    for (std::size_t i = 0; i + 5 < lines.size(); ++i)
      out << lines[i] << "\n";  // the last 5 views lost
  }
  const auto dir = fresh_dir();
  auto m = PerceptualMemory::open(dir, small_config(), OpenMode::CREATE);
  ASSERT_TRUE(m);
  auto imported = m->import_from(cut);
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, Code::BAD_IMPORT);
  EXPECT_NE(imported.error().message.find("says 12 views"), std::string::npos)
      << imported.error().message;
  EXPECT_EQ(m->stats().views, 0U);
}

TEST(MemoryImport, TheSameExportTwiceIsRefusedTheSecondTime) {
  const std::string file = exported("_src");
  const auto dir = fresh_dir();
  {
    auto m = PerceptualMemory::open(dir, small_config(), OpenMode::CREATE);
    ASSERT_TRUE(m);
    ASSERT_EQ(*m->import_from(file), 12U);
  }
  auto m =
      PerceptualMemory::open(dir, small_config(), OpenMode::READ_WRITE);  // also after a reopen
  ASSERT_TRUE(m);
  auto again = m->import_from(file);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.error().code, Code::BAD_IMPORT);
  EXPECT_NE(again.error().message.find("already"), std::string::npos) << again.error().message;
  EXPECT_EQ(m->stats().views, 12U);
}

}  // namespace
}  // namespace orthoflow::learning
