// The bounded regular-file reader (core/regular_file.hpp): what it reads is exactly the file; a
// FIFO (with or without a writer), a device, a directory, a missing file and a file over the limit
// are refused at once with their reason, never waited on or read without end.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/regular_file.hpp"

namespace orthoflow::core {
namespace {

namespace fs = std::filesystem;
using Code = FileReadFailure::Code;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("orthoflow_regular_file_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Code code_of(const fs::path& path, std::size_t limit = 1 << 20) {
  std::vector<char> out;
  auto read = read_regular_file(path, limit, out);
  EXPECT_FALSE(read.has_value()) << path;
  if (read) return Code::OPEN_FAILED;
  EXPECT_EQ(read.error().message.rfind(path.string() + ": ", 0), 0U) << read.error().message;
  return read.error().code;
}

TEST(RegularFile, ReadsExactlyTheFileUpToTheLimit) {
  const auto dir = scratch("read");
  std::string bytes(100'000, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7);
  std::ofstream(dir / "f", std::ios::binary) << bytes;
  auto text = read_regular_text(dir / "f", bytes.size());
  ASSERT_TRUE(text.has_value());
  EXPECT_EQ(*text, bytes);
  EXPECT_EQ(code_of(dir / "f", bytes.size() - 1), Code::TOO_LARGE);
  std::ofstream(dir / "empty").close();
  auto empty = read_regular_text(dir / "empty", 0);
  ASSERT_TRUE(empty.has_value());
  EXPECT_TRUE(empty->empty());
}

TEST(RegularFile, RefusesFifosDevicesDirectoriesAndMissingFilesAtOnce) {
  const auto dir = scratch("kinds");
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  EXPECT_EQ(code_of(dir / "fifo"), Code::NOT_REGULAR);  // no writer: must not wait for one
  const int writer = ::open((dir / "fifo").c_str(), O_RDWR | O_NONBLOCK);
  ASSERT_GE(writer, 0);
  ASSERT_EQ(::write(writer, "abc", 3), 3);
  EXPECT_EQ(code_of(dir / "fifo"), Code::NOT_REGULAR);  // a writer and data: still not a file
  ::close(writer);
  EXPECT_EQ(code_of("/dev/zero"), Code::NOT_REGULAR);  // endless
  EXPECT_EQ(code_of("/dev/null"), Code::NOT_REGULAR);
  EXPECT_EQ(code_of(dir), Code::NOT_REGULAR);
  EXPECT_EQ(code_of(dir / "missing"), Code::OPEN_FAILED);
}

}  // namespace
}  // namespace orthoflow::core
