// The camera tap (graphs/nodes/camera_tap.hpp): copies only while a viewer asks and no faster than
// it asked, subsamples by the smallest step that fits, keeps colour when the frame has it, skips
// unorganized frames, and hands out only images newer than the viewer has.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "graphs/nodes/camera_tap.hpp"

namespace orthoflow::graphs {
namespace {

constexpr std::int64_t MS = 1'000'000;

// A width x height frame whose point at pixel (u, v) is (u, v, 1 + u + v) and colour u * 1000 + v.
struct Frame {
  Frame(std::uint32_t width, std::uint32_t height, bool colour) {
    const std::size_t n = static_cast<std::size_t>(width) * height;
    x.resize(n);
    y.resize(n);
    z.resize(n);
    if (colour) rgb.resize(n);
    for (std::uint32_t v = 0; v < height; ++v) {
      for (std::uint32_t u = 0; u < width; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * width + u;
        x[i] = static_cast<float>(u);
        y[i] = static_cast<float>(v);
        z[i] = static_cast<float>(1 + u + v);
        if (colour) rgb[i] = u * 1000 + v;
      }
    }
    header.width = width;
    header.height = height;
  }
  engine::FrameView view(std::uint64_t id) {
    header.frame_id = id;
    engine::FrameView f;
    f.header = &header;
    f.cloud.points = {x, y, z};
    f.cloud.width = header.width;
    f.cloud.height = header.height;
    f.rgb = rgb;
    return f;
  }
  engine::FrameHeader header;
  std::vector<float> x, y, z;
  std::vector<std::uint32_t> rgb;
};

TEST(CameraTap, CopiesOnlyWhileAViewerAsksAndNoFasterThanAsked) {
  CameraTap tap(320, 240);
  Frame frame(640, 480, true);
  CameraImage image;
  EXPECT_FALSE(tap.offer(frame.view(1), 0));  // nobody asked: nothing copied, nothing allocated
  EXPECT_FALSE(tap.take(image, 0));
  tap.request(0, 100 * MS, 1000 * MS);
  EXPECT_TRUE(tap.offer(frame.view(2), 10 * MS));
  EXPECT_FALSE(tap.offer(frame.view(3), 50 * MS));  // sooner than the 100 ms asked for
  EXPECT_TRUE(tap.offer(frame.view(4), 110 * MS));
  EXPECT_FALSE(tap.offer(frame.view(5), 1000 * MS));  // the viewer stopped asking
  EXPECT_EQ(tap.copied(), 2U);
  ASSERT_TRUE(tap.take(image, 0));
  EXPECT_EQ(image.frame_id, 4U);
  EXPECT_FALSE(tap.take(image, 4));  // nothing newer than what the viewer has
}

TEST(CameraTap, SubsamplesByTheSmallestStepThatFits) {
  for (const auto& [w, h, step] : std::vector<std::array<std::uint32_t, 3>>{
           {640, 480, 2}, {320, 240, 1}, {641, 480, 3}, {1280, 960, 4}, {100, 1000, 5}}) {
    CameraTap tap(320, 240);
    tap.request(0, 0, 1000 * MS);
    Frame frame(w, h, false);
    ASSERT_TRUE(tap.offer(frame.view(7), 1));
    CameraImage image;
    ASSERT_TRUE(tap.take(image, 0));
    EXPECT_EQ(image.step, step) << w << "x" << h;
    EXPECT_EQ(image.width, w / step);
    EXPECT_EQ(image.height, h / step);
    EXPECT_LE(image.width, 320U);
    EXPECT_LE(image.height, 240U);
    EXPECT_TRUE(image.rgb.empty());  // no colour in the frame
    // Pixel (i, j) of the image is pixel (i * step, j * step) of the frame.
    const std::uint32_t i = image.width - 1, j = image.height - 1;
    const std::size_t k = static_cast<std::size_t>(j) * image.width + i;
    EXPECT_EQ(image.x[k], static_cast<float>(i * step));
    EXPECT_EQ(image.y[k], static_cast<float>(j * step));
    EXPECT_EQ(image.z[k], static_cast<float>(1 + (i + j) * step));
  }
}

TEST(CameraTap, KeepsColourAndNaNsAndSkipsUnorganizedFrames) {
  CameraTap tap(320, 240);
  tap.request(0, 0, 1000 * MS);
  Frame frame(640, 480, true);
  frame.z[2 * 640 + 2] = std::numeric_limits<float>::quiet_NaN();
  ASSERT_TRUE(tap.offer(frame.view(1), 1));
  CameraImage image;
  ASSERT_TRUE(tap.take(image, 0));
  ASSERT_EQ(image.rgb.size(), image.z.size());
  EXPECT_EQ(image.rgb[1 * 320 + 3], 6U * 1000 + 2);  // pixel (3, 1) is frame pixel (6, 2)
  EXPECT_TRUE(std::isnan(image.z[1 * 320 + 1]));
  Frame line(5000, 1, false);  // an unorganized cloud has no camera view
  EXPECT_FALSE(tap.offer(line.view(2), 2));
  Frame empty(0, 0, false);
  EXPECT_FALSE(tap.offer(empty.view(3), 3));
  EXPECT_FALSE(tap.take(image, 1));  // still frame 1
}

}  // namespace
}  // namespace orthoflow::graphs
