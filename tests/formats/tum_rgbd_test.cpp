// The TUM RGB-D benchmark's layout: 16-bit depth PNGs round trip every value and anything else is
// refused with a reason; depth.txt and associate.txt (either column order) list the depth images
// in time order, lines out of order are skipped and counted, and a listing that names a file
// outside the folder, or a time that is not a time, is an error naming the line.
#include <gtest/gtest.h>

#include <unistd.h>
#include <array>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include "formats/file_bytes.hpp"
#include "formats/png_depth.hpp"
#include "formats/tum_rgbd.hpp"

namespace orthoflow::formats {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const auto dir =
      fs::temp_directory_path() / ("orthoflow_tum_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<char> png_of(const std::vector<std::uint16_t>& values, std::uint32_t w,
                         std::uint32_t h) {
  const auto dir = scratch("png");
  EXPECT_TRUE(write_png_depth16(dir / "d.png", values, w, h).has_value());
  auto bytes = read_file_bytes(dir / "d.png");
  EXPECT_TRUE(bytes.has_value());
  return bytes ? *bytes : std::vector<char>{};
}

/// CRC-32 of PNG chunks (ISO 3309), to forge headers that are well formed but lie.
std::uint32_t crc32(const char* data, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFU;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= static_cast<std::uint8_t>(data[i]);
    for (int k = 0; k < 8; ++k) c = (c >> 1U) ^ (0xEDB88320U & (0U - (c & 1U)));
  }
  return c ^ 0xFFFFFFFFU;
}

/// Rewrites IHDR byte @p offset (0 = first data byte) to @p value and fixes the chunk's CRC.
std::vector<char> forge_ihdr(std::vector<char> png, std::size_t offset, std::uint8_t value) {
  png[16 + offset] = static_cast<char>(value);
  const std::uint32_t c = crc32(png.data() + 12, 17);
  for (int k = 0; k < 4; ++k) png[29 + k] = static_cast<char>(c >> (24 - 8 * k));
  return png;
}

TEST(PngDepth, RoundTripsEveryValueInHostOrder) {
  std::vector<std::uint16_t> values(std::size_t{TUM_WIDTH} * TUM_HEIGHT);
  std::mt19937 rng(5);
  for (auto& v : values) v = static_cast<std::uint16_t>(rng());
  values[0] = 0;
  values[1] = 0xFFFF;
  values[2] = 0x0102;  // byte order: 258, not 513
  const auto png = png_of(values, TUM_WIDTH, TUM_HEIGHT);
  std::vector<std::uint16_t> back(values.size(), 7);
  ASSERT_TRUE(parse_png_depth16(png, "d.png", TUM_WIDTH, TUM_HEIGHT, back).has_value());
  EXPECT_EQ(back, values);
}

TEST(PngDepth, RefusesWhatIsNotA16BitGreyImageOfTheExpectedSize) {
  const std::vector<std::uint16_t> small(16 * 8, 1000);
  const auto png = png_of(small, 16, 8);
  std::vector<std::uint16_t> out(16 * 8);
  ASSERT_TRUE(parse_png_depth16(png, "d.png", 16, 8, out).has_value());
  const auto code = [&](const std::vector<char>& bytes, std::uint32_t w, std::uint32_t h) {
    std::vector<std::uint16_t> o(std::size_t{w} * h);
    auto r = parse_png_depth16(bytes, "d.png", w, h, o);
    EXPECT_FALSE(r.has_value());
    return r ? IoError::Code::BAD_HEADER : r.error().code;
  };
  EXPECT_EQ(code(png, 8, 16), IoError::Code::SIZE_MISMATCH);
  EXPECT_EQ(code(forge_ihdr(png, 8, 8), 16, 8), IoError::Code::UNSUPPORTED);      // 8-bit
  EXPECT_EQ(code(forge_ihdr(png, 9, 2), 16, 8), IoError::Code::UNSUPPORTED);      // RGB
  EXPECT_EQ(code(forge_ihdr(png, 9, 4), 16, 8), IoError::Code::UNSUPPORTED);      // grey + alpha
  EXPECT_EQ(code(forge_ihdr(png, 1, 0xFF), 16, 8), IoError::Code::CORRUPT_DATA);  // 16 M wide
  EXPECT_EQ(code({}, 16, 8), IoError::Code::BAD_HEADER);
  EXPECT_EQ(code(std::vector<char>(png.begin(), png.begin() + 7), 16, 8),
            IoError::Code::BAD_HEADER);
  const std::string pgm = "P5 16 8 65535\n";
  EXPECT_EQ(code(std::vector<char>(pgm.begin(), pgm.end()), 16, 8), IoError::Code::BAD_HEADER);
  for (std::size_t cut : {std::size_t{20}, std::size_t{40}, png.size() - 13}) {
    const auto c =
        code(std::vector<char>(png.begin(), png.begin() + static_cast<long>(cut)), 16, 8);
    EXPECT_TRUE(c == IoError::Code::TRUNCATED || c == IoError::Code::CORRUPT_DATA) << cut;
  }
  auto flipped = png;
  flipped[png.size() - 20] = static_cast<char>(flipped[png.size() - 20] ^ 0x40);  // in IDAT
  EXPECT_EQ(code(flipped, 16, 8), IoError::Code::CORRUPT_DATA);
}

TEST(TumList, DepthTxtWithTheBenchmarksComments) {
  const std::string text =
      "# depth maps\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n"
      "1305031102.160407 depth/1305031102.160407.png\r\n"
      "1305031102.194330 depth/1305031102.194330.png\n\n";
  auto list = parse_tum_depth_list(text, "depth.txt", false);
  ASSERT_TRUE(list.has_value()) << list.error().to_string();
  ASSERT_EQ(list->entries.size(), 2U);
  EXPECT_DOUBLE_EQ(list->entries[0].seconds, 1305031102.160407);
  EXPECT_EQ(list->entries[1].file, "depth/1305031102.194330.png");
  EXPECT_EQ(list->out_of_order, 0U);
}

TEST(TumList, AssociateTxtInEitherColumnOrder) {
  const std::string rgb_first =
      "1.0 rgb/1.0.png 1.01 depth/1.01.png\n2.0 rgb/2.0.png 2.02 depth/2.02.png 9 9 9\n";
  const std::string depth_first = "1.01 depth/1.01.png 1.0 rgb/1.0.png\n";
  auto a = parse_tum_depth_list(rgb_first, "associate.txt", true);
  auto b = parse_tum_depth_list(depth_first, "associate.txt", true);
  ASSERT_TRUE(a.has_value() && b.has_value());
  ASSERT_EQ(a->entries.size(), 2U);
  EXPECT_DOUBLE_EQ(a->entries[1].seconds, 2.02);
  EXPECT_EQ(a->entries[1].file, "depth/2.02.png");
  ASSERT_EQ(b->entries.size(), 1U);
  EXPECT_EQ(b->entries[0].file, "depth/1.01.png");
  EXPECT_FALSE(parse_tum_depth_list("1 rgb/a.png 2 rgb/b.png\n", "a", true).has_value());
  EXPECT_FALSE(parse_tum_depth_list("1 depth/a.png 2 depth/b.png\n", "a", true).has_value());
  EXPECT_FALSE(parse_tum_depth_list("1 depth/a.png 2\n", "a", true).has_value());
}

TEST(TumList, LinesOutOfTimeOrderAreSkippedAndCounted) {
  const std::string text =
      "1.0 depth/a.png\n3.0 depth/c.png\n2.0 depth/b.png\n3.0 depth/c2.png\n4.0 depth/d.png\n";
  auto list = parse_tum_depth_list(text, "depth.txt", false);
  ASSERT_TRUE(list.has_value());
  ASSERT_EQ(list->entries.size(), 3U);
  EXPECT_EQ(list->entries[2].file, "depth/d.png");
  EXPECT_EQ(list->out_of_order, 2U);
}

TEST(TumList, RefusesFilesOutsideTheFolderAndTimesThatAreNotTimes) {
  for (const char* line :
       {"1.0 /etc/passwd.png", "1.0 ../secret.png", "1.0 depth/../../x.png", "1.0 depth//x.png",
        "1.0 depth/x.pgm", "1.0 depth/x\x01.png", "1.0 depth\\x.png", "nan depth/x.png",
        "inf depth/x.png", "-1 depth/x.png", "1e12 depth/x.png", "1.0x depth/x.png",
        "1.0 depth/x.png extra", "1.0"}) {
    auto list = parse_tum_depth_list(std::string(line) + "\n", "depth.txt", false);
    ASSERT_FALSE(list.has_value()) << line;
    EXPECT_NE(list.error().message.find("depth.txt: line 1: "), std::string::npos) << line;
  }
}

TEST(TumList, TheFolderPrefersAssociateTxtAndRefusesAnEmptyListing) {
  const auto dir = scratch("folder");
  EXPECT_FALSE(read_tum_depth_list(dir).has_value());  // neither listing
  std::ofstream(dir / "depth.txt") << "# only comments\n";
  auto empty = read_tum_depth_list(dir);
  ASSERT_FALSE(empty.has_value());
  EXPECT_NE(empty.error().message.find("lists no depth image"), std::string::npos);
  std::ofstream(dir / "depth.txt") << "1.0 depth/a.png\n2.0 depth/b.png\n";
  std::ofstream(dir / "associate.txt") << "2.0 depth/b.png 2.01 rgb/b.png\n";
  auto list = read_tum_depth_list(dir);
  ASSERT_TRUE(list.has_value());
  EXPECT_EQ(list->listing, "associate.txt");
  ASSERT_EQ(list->entries.size(), 1U);
  EXPECT_EQ(list->entries[0].file, "depth/b.png");
}

}  // namespace
}  // namespace orthoflow::formats
