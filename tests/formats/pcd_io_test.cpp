#include "formats/pcd_io.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <string>

#include "test_clouds.hpp"

namespace ofmt = orthoflow::formats;
namespace ok = orthoflow::kernels;
using orthoflow::test::expect_same_cloud;
using orthoflow::test::make_cloud;

namespace {

struct RoundTripCase {
  ofmt::PcdEncoding encoding;
  std::uint32_t width;
  std::uint32_t height;
  bool all_fields;
};

class PcdRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(PcdRoundTrip, ReadsBackWhatItWrote) {
  const RoundTripCase p = GetParam();
  const ok::PointCloud cloud = make_cloud(p.width, p.height, p.all_fields, p.width * 31 + p.height);
  const std::string bytes = ofmt::encode_pcd(cloud, p.encoding);
  auto read_result = ofmt::read_pcd_buffer(bytes, "roundtrip");
  ASSERT_TRUE(read_result) << read_result.error().to_string();
  expect_same_cloud(cloud, *read_result);
  EXPECT_EQ(read_result->info.viewpoint, cloud.info.viewpoint);
}

std::vector<RoundTripCase> round_trip_cases() {
  std::vector<RoundTripCase> cases;
  for (auto e : {ofmt::PcdEncoding::ASCII, ofmt::PcdEncoding::BINARY,
                 ofmt::PcdEncoding::BINARY_COMPRESSED}) {
    for (bool all : {false, true}) {
      cases.push_back({e, 0, 0, all});     // empty
      cases.push_back({e, 1, 1, all});     // one point
      cases.push_back({e, 1000, 1, all});  // unorganized
      cases.push_back({e, 64, 48, all});   // organized
    }
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Encodings, PcdRoundTrip, ::testing::ValuesIn(round_trip_cases()));

TEST(PcdIo, WritesAndReadsFiles) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("orthoflow_pcd_io_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const ok::PointCloud cloud = make_cloud(20, 10, true, 5);
  const auto path = dir / "cloud.pcd";
  ASSERT_TRUE(ofmt::write_pcd(cloud, path));
  EXPECT_FALSE(std::filesystem::exists(dir / "cloud.pcd.tmp"));
  auto read_result = ofmt::read_pcd(path);
  ASSERT_TRUE(read_result) << read_result.error().to_string();
  expect_same_cloud(cloud, *read_result);
  auto header_result = ofmt::read_pcd_header(path);
  ASSERT_TRUE(header_result);
  EXPECT_EQ(header_result->encoding, ofmt::PcdEncoding::BINARY_COMPRESSED);
  EXPECT_EQ(header_result->fields.size(), 8U);
  std::filesystem::remove_all(dir);
}

TEST(PcdIo, ReadsVersion06AndUnknownFieldsAndCounts) {
  // 0.6 header without VIEWPOINT; an unknown multi-count field and a double field are read past.
  const std::string text =
      "VERSION .6\nFIELDS x hist y z intensity\nSIZE 4 2 8 4 1\nTYPE F U F F U\nCOUNT 1 3 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1.5 1 2 3 -2.25 nan 7\n\n-0 4 5 6 1e-3 inf 255\n";
  auto r = ofmt::read_pcd_buffer(text, "v06");
  ASSERT_TRUE(r) << r.error().to_string();
  ASSERT_EQ(r->size(), 2U);
  EXPECT_EQ(r->x()[0], 1.5F);
  EXPECT_EQ(r->y()[0], -2.25F);
  EXPECT_TRUE(std::isnan(r->z()[0]));
  EXPECT_EQ(r->y()[1], 1e-3F);
  EXPECT_TRUE(std::isinf(r->z()[1]));
  EXPECT_TRUE(std::signbit(r->x()[1]));
  EXPECT_FALSE(r->has(ok::Field::RGB));
}

TEST(PcdIo, ReadsRgbDeclaredAsFloatBitForBit) {
  // PCL writes rgb as F 4; its bits are the colour.
  ok::PointCloud c;
  c.resize(1, 1);
  const std::uint32_t colour = 0x00FF8040U;
  float as_float = 0;
  std::memcpy(&as_float, &colour, 4);
  std::string text =
      "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 1\nHEIGHT 1\nDATA binary\n";
  const float rec[4] = {1.0F, 2.0F, 3.0F, as_float};
  text.append(reinterpret_cast<const char*>(rec), sizeof(rec));
  auto r = ofmt::read_pcd_buffer(text, "rgbf");
  ASSERT_TRUE(r) << r.error().to_string();
  ASSERT_TRUE(r->has(ok::Field::RGB));
  EXPECT_EQ(r->rgb()[0], colour);
}

}  // namespace
