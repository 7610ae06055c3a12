// The stage objects of kernels/tabletop_stages.hpp on hand-made inputs: every SegmentationError
// code is triggered and named (STYLE rule 9), the kernel's reason is kept, and a full-frame
// stride-1 sample without room for the scoring sample falls back to scoring on the dense sample.
// Narrow organized frames and frames outside the ROI: narrow_frames_test.cpp.
#include "kernels/tabletop_stages.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace ok = orthoflow::kernels;
using Code = ok::SegmentationError::Code;

namespace {

/// An organized w x h frame of a table at z = 1 m (x, y in [-0.4, 0.4]), with a 10 cm box on it.
struct Frame {
  std::vector<float> x, y, z;
  std::uint32_t w, h;
  Frame(std::uint32_t width, std::uint32_t height) : w(width), h(height) {
    for (std::uint32_t v = 0; v < h; ++v) {
      for (std::uint32_t u = 0; u < w; ++u) {
        const float px = -0.4F + 0.8F * static_cast<float>(u) / static_cast<float>(w - 1);
        const float py = -0.4F + 0.8F * static_cast<float>(v) / static_cast<float>(h - 1);
        const bool box = px > -0.05F && px < 0.05F && py > -0.05F && py < 0.05F;
        x.push_back(px);
        y.push_back(py);
        z.push_back(box ? 0.9F : 1.0F);
      }
    }
  }
  ok::CloudView view() const { return {{x, y, z}, w, h}; }
};

struct Buffers {
  std::vector<float> x, y, z;
  explicit Buffers(std::size_t n) : x(n), y(n), z(n) {}
  ok::PointsSpan span() { return {x, y, z}; }
};

TEST(TabletopStages, EveryCodeHasAName) {
  for (const Code c :
       {Code::CLOUD_TOO_LARGE, Code::NOT_WIDTH_X_HEIGHT, Code::OUTPUT_TOO_SMALL,
        Code::VOXEL_GRID_FAILED, Code::NO_PLANE, Code::FEW_SAMPLE_INLIERS, Code::DEGENERATE_HULL,
        Code::HULL_TOO_LARGE, Code::CLUSTERING_FAILED, Code::FEW_POINTS_IN_ROI}) {
    EXPECT_NE(ok::to_string(c), "UNKNOWN");
    const ok::SegmentationError e{c, 0, 0.0, 0, 0};
    EXPECT_NE(e.to_string().find(std::string(ok::to_string(c))), std::string::npos);
  }
}

TEST(TabletopStages, PlaneInputErrors) {
  const Frame f(64, 48);
  ok::SegmentationParams p;
  ok::PlaneInputStage small(100);
  Buffers out(64 * 48);
  EXPECT_EQ(small.run(f.view(), p, out.span()).error().code, Code::CLOUD_TOO_LARGE);
  ok::PlaneInputStage stage(64 * 48);
  Buffers tiny(10);
  EXPECT_EQ(stage.run(f.view(), p, tiny.span()).error().code, Code::OUTPUT_TOO_SMALL);
  ok::SegmentationParams voxel = p;
  voxel.use_organized = false;
  voxel.leaf = -1.0F;  // voxel_grid refuses it: the kernel's reason is kept
  const auto bad_leaf = stage.run(f.view(), voxel, out.span());
  ASSERT_FALSE(bad_leaf);
  EXPECT_EQ(bad_leaf.error().code, Code::VOXEL_GRID_FAILED);
  EXPECT_EQ(bad_leaf.error().cause,
            static_cast<std::uint8_t>(ok::VoxelGridError::Code::INVALID_LEAF));
  EXPECT_NE(bad_leaf.error().to_string().find("voxel"), std::string::npos)
      << bad_leaf.error().to_string();
}

TEST(TabletopStages, AFullFrameStrideOneSampleScoresOnTheDenseSample) {
  const Frame f(64, 48);
  ok::SegmentationParams p;
  p.organized_stride = 1;
  ok::PlaneInputStage stage(64 * 48);
  Buffers out(64 * 48);  // room for the dense sample only
  const auto input = stage.run(f.view(), p, out.span());
  ASSERT_TRUE(input) << input.error().to_string();
  EXPECT_EQ(input->dense.size(), 64U * 48U);
  EXPECT_TRUE(input->sparse.empty());
  ok::TableStage table(64 * 48);
  std::vector<double> hu(64 * 48 + 1), hv(64 * 48 + 1);
  EXPECT_TRUE(table.run(*input, p, hu, hv));
}

TEST(TabletopStages, TableErrors) {
  ok::SegmentationParams p;
  ok::TableStage table(2000);
  std::vector<double> hu(2001), hv(2001);
  std::vector<float> two{0.0F, 1.0F};
  const ok::PlaneInput few{{two, two, two}, {}, 2};
  const auto none = table.run(few, p, hu, hv);
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().code, Code::NO_PLANE);
  EXPECT_EQ(none.error().cause, static_cast<std::uint8_t>(ok::RansacError::Code::TOO_FEW_POINTS));
  // Counts print as integers (issue 16: "2.000000 finite points").
  EXPECT_NE(none.error().to_string().find("ransac_plane: 2 finite points"), std::string::npos)
      << none.error().to_string();
  // A 600-point planar scoring sample at z = 1, and a dense sample far from that plane: the refit
  // finds fewer than 3 inliers on the dense sample.
  std::vector<float> sx, sy, sz, dx, dy, dz;
  for (int i = 0; i < 600; ++i) {
    sx.push_back(static_cast<float>(i % 30) * 0.01F);
    sy.push_back(static_cast<float>(i / 30) * 0.01F);
    sz.push_back(1.0F);
  }
  for (int i = 0; i < 50; ++i) {
    dx.push_back(static_cast<float>(i) * 0.01F);
    dy.push_back(0.0F);
    dz.push_back(2.0F);
  }
  const ok::PlaneInput off{{dx, dy, dz}, {sx, sy, sz}, 50};
  EXPECT_EQ(table.run(off, p, hu, hv).error().code, Code::FEW_SAMPLE_INLIERS);
  // The dense sample on the plane but on one line: its hull is degenerate.
  std::vector<float> lz(50, 1.0F);
  const ok::PlaneInput line{{dx, dy, lz}, {sx, sy, sz}, 50};
  EXPECT_EQ(table.run(line, p, hu, hv).error().code, Code::DEGENERATE_HULL);
  // A proper table, but only 2 hull slots in the caller's span.
  const ok::PlaneInput plane{{sx, sy, sz}, {}, 600};
  std::vector<double> two_u(2), two_v(2);
  EXPECT_EQ(table.run(plane, p, two_u, two_v).error().code, Code::HULL_TOO_LARGE);
}

TEST(TabletopStages, ObjectStageKeepsTheClusteringReason) {
  const Frame f(64, 48);
  ok::SegmentationParams p;
  ok::PlaneInputStage input_stage(64 * 48);
  Buffers out(64 * 48);
  const auto input = input_stage.run(f.view(), p, out.span());
  ASSERT_TRUE(input);
  ok::TableStage table_stage(64 * 48);
  std::vector<double> hu(64 * 48 + 1), hv(64 * 48 + 1);
  const auto table = table_stage.run(*input, p, hu, hv);
  ASSERT_TRUE(table);
  ok::ObjectStage objects(64 * 48, p.cluster.min_size);
  ok::SegmentationParams bad = p;
  bad.cluster.tolerance = 0.0F;
  const auto failed = objects.run(f.view(), *input, *table, bad);
  ASSERT_FALSE(failed);
  EXPECT_EQ(failed.error().code, Code::CLUSTERING_FAILED);
  EXPECT_EQ(failed.error().cause, static_cast<std::uint8_t>(ok::ClusterError::Code::BAD_PARAMS));
  ok::ObjectStage tiny(10, 1);
  EXPECT_EQ(tiny.run(f.view(), *input, *table, p).error().code, Code::CLOUD_TOO_LARGE);
}

}  // namespace
