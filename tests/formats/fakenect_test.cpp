// libfreenect's fakenect recording format: round trips of every record kind, the exact bytes
// fakenect writes, and strict refusal of what is not a fakenect record.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include "formats/fakenect.hpp"
#include "formats/file_bytes.hpp"

namespace orthoflow::formats {
namespace {

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("orthoflow_fakenect_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

TEST(Fakenect, NamesFollowTheFakenectPattern) {
  EXPECT_EQ(fakenect_name('d', 1234.5, 2000000), "d-1234.500000-2000000.pgm");
  EXPECT_EQ(fakenect_name('r', 0.000001, 7), "r-0.000001-7.ppm");
  EXPECT_EQ(fakenect_name('a', 12.0, 4294967295U), "a-12.000000-4294967295.dump");
}

TEST(Fakenect, DepthRoundTripIsHostOrderWithTheFakenectHeader) {
  const auto dir = scratch("depth");
  std::vector<std::uint16_t> raw(FAKENECT_PIXELS);
  std::mt19937 rng(3);
  for (auto& v : raw) v = static_cast<std::uint16_t>(rng() % 2048);
  raw[0] = 2047;
  raw[1] = 0x0102;
  ASSERT_TRUE(write_fakenect_depth(dir / "d.pgm", raw).has_value());
  auto bytes = read_file_bytes(dir / "d.pgm");
  ASSERT_TRUE(bytes.has_value());
  ASSERT_EQ(bytes->size(), 17 + FAKENECT_PIXELS * 2);
  EXPECT_EQ(std::string(bytes->data(), 17), "P5 640 480 65535\n");
  EXPECT_EQ(static_cast<unsigned char>((*bytes)[17 + 2]), 0x02);  // little-endian, as fakenect
  EXPECT_EQ(static_cast<unsigned char>((*bytes)[17 + 3]), 0x01);
  std::vector<std::uint16_t> back(FAKENECT_PIXELS);
  ASSERT_TRUE(read_fakenect_depth(dir / "d.pgm", back).has_value());
  EXPECT_EQ(back, raw);
  raw[5] = 4000;
  EXPECT_EQ(write_fakenect_depth(dir / "bad.pgm", raw).error().code, IoError::Code::BAD_NUMBER);
}

TEST(Fakenect, DepthReaderRefusesWhatIsNotARecord) {
  const auto dir = scratch("depth_bad");
  std::vector<std::uint16_t> out(FAKENECT_PIXELS);
  write_text(dir / "short.pgm", "P5 640 480 65535\n" + std::string(100, '\0'));
  EXPECT_EQ(read_fakenect_depth(dir / "short.pgm", out).error().code, IoError::Code::TRUNCATED);
  write_text(dir / "head.pgm", "P5 320 240 65535\n" + std::string(320 * 240 * 2, '\0'));
  const auto head = read_fakenect_depth(dir / "head.pgm", out);
  EXPECT_EQ(head.error().code, IoError::Code::BAD_HEADER);
  EXPECT_NE(head.error().message.find("head.pgm"), std::string::npos);
  // A standard big-endian PGM of 11-bit values reads as values > 2047: refused, not garbage.
  std::string be(FAKENECT_PIXELS * 2, '\0');
  be[2] = 0x00;
  be[3] = 0x08;  // big-endian 8 read little-endian: 0x0800 = 2048
  write_text(dir / "be.pgm", "P5 640 480 65535\n" + be);
  EXPECT_EQ(read_fakenect_depth(dir / "be.pgm", out).error().code, IoError::Code::BAD_NUMBER);
  EXPECT_FALSE(read_fakenect_depth(dir / "missing.pgm", out).has_value());
}

TEST(Fakenect, RgbAndTiltRoundTrip) {
  const auto dir = scratch("other");
  std::vector<std::uint8_t> rgb(FAKENECT_PIXELS * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i * 7);
  ASSERT_TRUE(write_fakenect_rgb(dir / "r.ppm", rgb).has_value());
  std::vector<std::uint8_t> rgb_back(rgb.size());
  ASSERT_TRUE(read_fakenect_rgb(dir / "r.ppm", rgb_back).has_value());
  EXPECT_EQ(rgb_back, rgb);

  const FakenectTilt tilt{-819, 12, 819, -40, 4};
  ASSERT_TRUE(write_fakenect_tilt(dir / "a.dump", tilt).has_value());
  EXPECT_EQ(std::filesystem::file_size(dir / "a.dump"), 12U);
  auto t = read_fakenect_tilt(dir / "a.dump");
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->accel_x, -819);
  EXPECT_EQ(t->accel_z, 819);
  EXPECT_EQ(t->tilt_half_degrees, -40);
  EXPECT_EQ(t->status, 4);
}

TEST(Fakenect, IndexParsesTheScheduleAndNamesBadLines) {
  const auto dir = scratch("index");
  write_text(dir / "INDEX.txt",
             "d-1.000000-100.pgm\nr-1.010000-200.ppm\r\n\na-1.020000-200.dump\n");
  auto index = read_fakenect_index(dir);
  ASSERT_TRUE(index.has_value()) << index.error().to_string();
  ASSERT_EQ(index->size(), 3U);
  EXPECT_EQ((*index)[0].kind, 'd');
  EXPECT_EQ((*index)[1].device_ticks, 200U);
  EXPECT_DOUBLE_EQ((*index)[2].host_seconds, 1.02);
  EXPECT_EQ((*index)[2].file, "a-1.020000-200.dump");
  for (const std::string bad : {"x-1.0-2.pgm", "d-abc-2.pgm", "d-1.0-2.ppm",
                                "d-1.0-99999999999.pgm", "../d-1.0-2.pgm", "d-1.0.pgm"}) {
    write_text(dir / "INDEX.txt", "d-1.000000-100.pgm\n" + bad + "\n");
    const auto r = read_fakenect_index(dir);
    ASSERT_FALSE(r.has_value()) << bad;
    EXPECT_NE(r.error().message.find("line 2"), std::string::npos) << r.error().message;
  }
  write_text(dir / "INDEX.txt", "\n\n");
  EXPECT_FALSE(read_fakenect_index(dir).has_value());
}

}  // namespace
}  // namespace orthoflow::formats
