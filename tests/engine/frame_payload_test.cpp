#include "engine/frame_payload.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace orthoflow::engine {
namespace {

struct alignas(64) Buffer {
  std::byte bytes[1 << 16];
};

kernels::PointCloud make_cloud(std::uint32_t w, std::uint32_t h) {
  kernels::PointCloud c;
  c.resize(w, h);
  c.add_field(kernels::Field::LABEL);
  for (std::size_t i = 0; i < c.size(); ++i) {
    c.x()[i] = static_cast<float>(i);
    c.y()[i] = -static_cast<float>(i);
    c.z()[i] = i % 3 == 0 ? NAN : 1.5F;
    c.label()[i] = static_cast<std::uint32_t>(i * 7);
  }
  c.info.frame_id = 42;
  c.info.sensor_stamp_ns = 1000;
  c.info.host_stamp_ns = 2000;
  return c;
}

TEST(FramePayload, RoundTripKeepsPointsFieldsAndStamps) {
  auto buffer = std::make_unique<Buffer>();
  const auto cloud = make_cloud(13, 7);
  auto written = write_frame(buffer->bytes, cloud);
  ASSERT_TRUE(written) << written.error().to_string();
  EXPECT_EQ(*written, frame_payload_bytes(13, 7, FRAME_FIELD_LABEL));
  auto view = view_frame(std::span<const std::byte>(buffer->bytes).first(*written));
  ASSERT_TRUE(view) << view.error().to_string();
  EXPECT_EQ(view->cloud.width, 13U);
  EXPECT_EQ(view->cloud.height, 7U);
  EXPECT_EQ(view->header->frame_id, 42U);
  EXPECT_EQ(view->header->sensor_stamp_ns, 1000);
  EXPECT_TRUE(view->rgb.empty());
  ASSERT_EQ(view->label.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_EQ(view->cloud.points.x[i], cloud.x()[i]);
    EXPECT_EQ(std::isnan(view->cloud.points.z[i]), std::isnan(cloud.z()[i]));
    EXPECT_EQ(view->label[i], cloud.label()[i]);
  }
}

TEST(FramePayload, EmptyCloudIsAValidFrame) {
  auto buffer = std::make_unique<Buffer>();
  auto written = write_frame(buffer->bytes, kernels::PointCloud{});
  ASSERT_TRUE(written);
  auto view = view_frame(std::span<const std::byte>(buffer->bytes).first(*written));
  ASSERT_TRUE(view);
  EXPECT_TRUE(view->cloud.points.empty());
}

TEST(FramePayload, RejectsWhatItCannotRead) {
  auto buffer = std::make_unique<Buffer>();
  std::span<std::byte> bytes(buffer->bytes);
  const auto cloud = make_cloud(8, 8);
  const std::size_t n = *write_frame(bytes, cloud);
  using Code = FrameError::Code;
  EXPECT_EQ(view_frame(bytes.first(n - 1)).error().code, Code::TOO_SMALL);
  EXPECT_EQ(view_frame(bytes.first(10)).error().code, Code::TOO_SMALL);
  EXPECT_EQ(view_frame(bytes.subspan(4, n)).error().code, Code::MISALIGNED);
  auto* header = reinterpret_cast<FrameHeader*>(bytes.data());
  header->version = 2;
  auto wrong_version = view_frame(bytes);
  EXPECT_EQ(wrong_version.error().code, Code::WRONG_VERSION);
  EXPECT_NE(wrong_version.error().to_string().find("version 2"), std::string::npos);
  header->version = FRAME_VERSION;
  header->type_id = 7;
  EXPECT_EQ(view_frame(bytes).error().code, Code::WRONG_TYPE);
  header->type_id = FRAME_TYPE_ID;
  header->width = 1U << 20;  // claims 2^23 points: the size no longer matches
  EXPECT_EQ(view_frame(bytes).error().code, Code::SIZE_MISMATCH);
  header->width = 1U << 30;
  EXPECT_EQ(view_frame(bytes).error().code, Code::BAD_SHAPE);
}

TEST(FramePayload, LayoutRefusesSmallBuffersAndHugeShapes) {
  auto buffer = std::make_unique<Buffer>();
  std::span<std::byte> bytes(buffer->bytes);
  EXPECT_EQ(layout_frame(bytes, 640, 480, 0).error().code, FrameError::Code::TOO_SMALL);
  EXPECT_EQ(layout_frame(bytes, 1U << 16, 1U << 16, 0).error().code, FrameError::Code::BAD_SHAPE);
  EXPECT_EQ(frame_payload_bytes(1U << 16, 1U << 16, 0), 0U);
  auto laid = layout_frame(bytes, 4, 4, FRAME_FIELD_RGB | FRAME_FIELD_LABEL);
  ASSERT_TRUE(laid);
  EXPECT_EQ(laid->rgb.size(), 16U);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(laid->points.y.data()) % 64, 0U);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(laid->label.data()) % 64, 0U);
}

}  // namespace
}  // namespace orthoflow::engine
