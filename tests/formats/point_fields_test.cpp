#include "formats/point_fields.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "test_clouds.hpp"

namespace ofmt = orthoflow::formats;
namespace ok = orthoflow::kernels;

namespace {

struct XYZRGBA {  // the layout of PCL's PointXYZRGBA, without PCL
  float x, y, z, pad;
  std::uint32_t rgba;
};

struct XYZ {
  float x, y, z;
};

TEST(PointFields, RecordsRoundTripThroughPointCloud2Layout) {
  const ok::PointCloud cloud = orthoflow::test::make_cloud(13, 1, true, 3);
  const auto fields = ofmt::fields_for(cloud);
  ASSERT_EQ(fields.size(), 8U);
  EXPECT_EQ(ofmt::packed_size(fields), 32U);
  std::vector<char> records(cloud.size() * ofmt::packed_size(fields));
  ofmt::encode_records(cloud, fields, records);
  ok::PointCloud back;
  back.resize(13, 1);
  ofmt::add_fields_for(fields, back);
  ofmt::decode_records(records, fields, ofmt::packed_size(fields), back);
  orthoflow::test::expect_same_cloud(cloud, back);
}

TEST(PointFields, DecodesIntegerAndDoubleFields) {
  // A PointCloud2-style record with a double x, int16 y, uint8 z and an ignored field.
  const std::vector<ofmt::PointField> fields = {{"x", 0, ofmt::ScalarType::FLOAT64, 1},
                                                {"y", 8, ofmt::ScalarType::INT16, 1},
                                                {"z", 10, ofmt::ScalarType::UINT8, 1},
                                                {"intensity", 11, ofmt::ScalarType::UINT8, 1}};
  char rec[12] = {};
  const double x = -2.5;
  const std::int16_t y = -300;
  std::memcpy(rec, &x, 8);
  std::memcpy(rec + 8, &y, 2);
  rec[10] = 7;
  ok::PointCloud c;
  c.resize(1, 1);
  ofmt::decode_records(std::span<const char>(rec, 12), fields, 12, c);
  EXPECT_EQ(c.x()[0], -2.5F);
  EXPECT_EQ(c.y()[0], -300.0F);
  EXPECT_EQ(c.z()[0], 7.0F);
}

TEST(PointFields, AdaptsArrayOfStructs) {
  const std::vector<XYZRGBA> pts = {{1, 2, 3, 0, 0xFF102030U}, {4, 5, 6, 0, 0x80FFFFFFU}};
  ok::PointCloud c;
  ofmt::from_aos<XYZRGBA>(pts, c);
  ASSERT_EQ(c.size(), 2U);
  EXPECT_EQ(c.y()[1], 5.0F);
  ASSERT_TRUE(c.has(ok::Field::RGB));
  EXPECT_EQ(c.rgb()[0], 0xFF102030U);
  std::vector<XYZRGBA> back(2);
  ofmt::to_aos<XYZRGBA>(c, back);
  EXPECT_EQ(back[1].rgba, 0x80FFFFFFU);
  ok::PointCloud plain;
  ofmt::from_aos<XYZ>(std::vector<XYZ>{{7, 8, 9}}, plain);
  EXPECT_FALSE(plain.has(ok::Field::RGB));
  EXPECT_EQ(plain.z()[0], 9.0F);
}

}  // namespace
