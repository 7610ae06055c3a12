// The whole-file writer (core/file_output.hpp): a regular file is replaced whole, with no temporary
// left behind; a device is written into and stays a device; a full device, a directory and a path
// under a regular file are errors naming the path, and a failed write leaves the old file intact.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/file_output.hpp"

namespace orthoflow::core {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("orthoflow_file_output_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string text_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool is_char_device(const char* path) {
  struct stat st {};
  return ::stat(path, &st) == 0 && S_ISCHR(st.st_mode);
}

TEST(FileOutput, ReplacesARegularFileWholeAndLeavesNoTemporary) {
  const auto dir = scratch("regular");
  const auto file = dir / "out.txt";
  ASSERT_TRUE(write_whole_file(file, "first version, longer than the second\n").has_value());
  ASSERT_TRUE(write_whole_file(file, "second\n", /*synced=*/true).has_value());
  EXPECT_EQ(text_of(file), "second\n");
  ASSERT_TRUE(write_whole_file(dir / "empty", "").has_value());
  EXPECT_EQ(fs::file_size(dir / "empty"), 0U);
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 2U);  // out.txt and empty, no .tmp
}

TEST(FileOutput, WritesIntoADeviceAndLeavesItADevice) {
  ASSERT_TRUE(is_char_device("/dev/null"));
  ASSERT_TRUE(write_whole_file("/dev/null", std::string(100'000, 'x')).has_value());
  EXPECT_TRUE(is_char_device("/dev/null"));
}

TEST(FileOutput, AFullDeviceIsAnErrorAndStaysADevice) {
  ASSERT_TRUE(is_char_device("/dev/full"));
  auto written = write_whole_file("/dev/full", "a line\n");
  ASSERT_FALSE(written.has_value());
  EXPECT_EQ(written.error().rfind("/dev/full: ", 0), 0U) << written.error();
  EXPECT_NE(written.error().find("No space left"), std::string::npos) << written.error();
  EXPECT_TRUE(is_char_device("/dev/full"));
}

TEST(FileOutput, ADirectoryOrAPathUnderAFileIsAnErrorAndTheOldFileStays) {
  const auto dir = scratch("refused");
  auto into_dir = write_whole_file(dir, "x");
  ASSERT_FALSE(into_dir.has_value());
  EXPECT_NE(into_dir.error().find("Is a directory"), std::string::npos) << into_dir.error();
  const auto file = dir / "keep.txt";
  ASSERT_TRUE(write_whole_file(file, "kept\n").has_value());
  auto under_file = write_whole_file(file / "x", "y");
  ASSERT_FALSE(under_file.has_value());
  EXPECT_EQ(under_file.error().rfind((file / "x").string() + ": ", 0), 0U) << under_file.error();
  EXPECT_EQ(text_of(file), "kept\n");
}

}  // namespace
}  // namespace orthoflow::core
