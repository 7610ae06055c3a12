// Narrow organized frames (issue 16): a strip of 1-10 columns (or rows) of a Kinect-like depth
// image of a table finds the table, as the same points as an unorganized cloud do. One column of a
// depth image lies in a plane through the camera, so the strided sample of such a strip (one or two
// columns) used to give that plane or no plane at all; the stage now takes every kept pixel there.
// Frames with too few points inside the ROI say how many are finite and how many are inside.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "kernels/segmentation_chain.hpp"
#include "kernels/tabletop_stages.hpp"

namespace ok = orthoflow::kernels;
using Code = ok::SegmentationError::Code;

namespace {

constexpr float NAN_F = std::numeric_limits<float>::quiet_NaN();

/// Pixels [u0, u0 + w) x [v0, v0 + h) of a 640 x 480 pinhole view (f = 525) of a table 1.1 m away,
/// tilted 50 degrees: normal (0, -sin 50, -cos 50), the Kinect-on-a-table geometry.
struct Strip {
  std::vector<float> x, y, z;
  std::uint32_t w, h;
  static constexpr float NY = -0.76604444F, NZ = -0.64278761F;
  static constexpr float D = -(NY * 0.35F + NZ * 1.1F);  // through (0, 0.35, 1.1)
  Strip(std::uint32_t u0, std::uint32_t width, std::uint32_t v0, std::uint32_t height)
      : w(width), h(height) {
    for (std::uint32_t v = v0; v < v0 + h; ++v) {
      for (std::uint32_t u = u0; u < u0 + w; ++u) {
        const float rx = (static_cast<float>(u) - 319.5F) / 525.0F;
        const float ry = (static_cast<float>(v) - 239.5F) / 525.0F;
        const float den = NY * ry + NZ;
        const float s = den < 0.0F ? -D / den : -1.0F;
        const bool hit = s > 0.0F && s < 3.0F;
        x.push_back(hit ? s * rx : NAN_F);
        y.push_back(hit ? s * ry : NAN_F);
        z.push_back(hit ? s : NAN_F);
      }
    }
  }
  ok::CloudView organized() const { return {{x, y, z}, w, h}; }
  ok::CloudView unorganized() const { return {{x, y, z}, w * h, 1}; }
};

/// The chain's plane normal on @p cloud (sign as found), or a failure.
testing::AssertionResult finds_table(ok::CloudView cloud) {
  ok::SegmentationChain chain(cloud.points.size(), ok::SegmentationParams{});
  const auto seg = chain.run(cloud);
  if (!seg) return testing::AssertionFailure() << seg.error().to_string();
  const auto& n = seg->plane.plane.normal;
  const float cosine = std::fabs(n[1] * Strip::NY + n[2] * Strip::NZ);
  if (cosine < 0.999F) {
    return testing::AssertionFailure()
           << "plane normal (" << n[0] << ", " << n[1] << ", " << n[2] << ") is not the table's";
  }
  return testing::AssertionSuccess();
}

TEST(NarrowFrames, SampleLinesCountsWhatPixelSubsampleTakes) {
  EXPECT_EQ(ok::sample_lines(0, 4), 0U);
  EXPECT_EQ(ok::sample_lines(2, 4), 0U);   // u = 2 is outside
  EXPECT_EQ(ok::sample_lines(3, 4), 1U);   // u = 2
  EXPECT_EQ(ok::sample_lines(10, 4), 2U);  // u = 2, 6
  EXPECT_EQ(ok::sample_lines(11, 4), 3U);  // u = 2, 6, 10
  EXPECT_EQ(ok::sample_lines(640, 4), 160U);
  EXPECT_EQ(ok::sample_lines(1, 1), 1U);
}

// From 2 columns or rows: the pixels of one lie on one line of the table, which no plane fit can
// tell from the other planes through that line.
TEST(NarrowFrames, ANarrowOrganizedStripFindsTheTableAsItsPointsDo) {
  for (std::uint32_t w = 2; w <= 12; ++w) {
    const Strip strip(320 - w / 2, w, 0, 480);
    EXPECT_TRUE(finds_table(strip.unorganized())) << w << " columns, unorganized";
    EXPECT_TRUE(finds_table(strip.organized())) << w << " columns, organized";
  }
  for (std::uint32_t h = 2; h <= 12; ++h) {
    const Strip strip(0, 640, 300, h);
    EXPECT_TRUE(finds_table(strip.organized())) << h << " rows, organized";
  }
}

TEST(NarrowFrames, OnlyNarrowFramesLeaveTheStridedSample) {
  ok::SegmentationParams p;  // stride 4
  // Rows 140-479: every pixel is finite and inside the ROI (z <= 2 m).
  const Strip narrow(316, 8, 140, 340), wide(310, 20, 140, 340);
  EXPECT_FALSE(ok::takes_strided_sample(narrow.organized(), p));
  EXPECT_TRUE(ok::takes_strided_sample(wide.organized(), p));
  EXPECT_FALSE(ok::takes_strided_sample(wide.unorganized(), p));
  ok::PlaneInputStage stage(wide.x.size());
  std::vector<float> ox(wide.x.size()), oy(ox.size()), oz(ox.size());
  const auto sampled = stage.run(wide.organized(), p, {ox, oy, oz});
  ASSERT_TRUE(sampled) << sampled.error().to_string();
  EXPECT_EQ(sampled->dense.size(), 5U * 85U);  // every 4th pixel of every 4th row
  const auto every = stage.run(narrow.organized(), p, {ox, oy, oz});
  ASSERT_TRUE(every) << every.error().to_string();
  EXPECT_EQ(every->kept, 8U * 340U);
  EXPECT_TRUE(every->sparse.empty());
  // The narrow frame is still labelled per pixel (image-space clustering on the organized path).
  ok::SegmentationChain chain(narrow.x.size(), p);
  const auto seg = chain.run(narrow.organized());
  ASSERT_TRUE(seg) << seg.error().to_string();
  EXPECT_TRUE(seg->organized);
  EXPECT_EQ(seg->labels.size(), narrow.x.size());
}

TEST(NarrowFrames, FewPointsInsideTheRoiSayWhatHappened) {
  Strip strip(300, 40, 100, 40);
  for (float& z : strip.z) z += 5.0F;  // finite, all beyond the ROI's 2 m
  ok::SegmentationParams p;
  for (const bool organized : {true, false}) {
    ok::PlaneInputStage stage(strip.x.size());
    std::vector<float> ox(strip.x.size()), oy(ox.size()), oz(ox.size());
    const auto r = stage.run(organized ? strip.organized() : strip.unorganized(), p, {ox, oy, oz});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, Code::FEW_POINTS_IN_ROI);
    EXPECT_EQ(r.error().finite, 1600U);
    EXPECT_EQ(r.error().value, 0.0);
    EXPECT_EQ(r.error().to_string(),
              "segmentation: FEW_POINTS_IN_ROI: 1600 finite points, 0 inside the region of "
              "interest x [-1, 1] y [-1, 1] z [0.3, 2] m; a plane needs at least 3");
  }
  // Two finite points inside, the rest NaN.
  std::vector<float> x(100, NAN_F), y(100, NAN_F), z(100, NAN_F);
  x[0] = y[0] = x[1] = 0.1F;
  y[1] = 0.0F;
  z[0] = z[1] = 1.0F;
  ok::SegmentationChain chain(100, p);
  const auto seg = chain.run({{x, y, z}, 10, 10});
  ASSERT_FALSE(seg);
  EXPECT_EQ(seg.error().code, Code::FEW_POINTS_IN_ROI);
  EXPECT_NE(seg.error().to_string().find("2 finite points, 2 inside"), std::string::npos)
      << seg.error().to_string();
}

}  // namespace
