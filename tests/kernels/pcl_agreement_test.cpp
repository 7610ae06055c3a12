// Agreement with PCL 1.13 on the mOSD frames with the same parameters (PCL in tests only):
// the same voxel set with centroids within 1e-5 m; plane normals within 1 degree and offsets within
// 5 mm; identical cluster partitions on the same points (the clustering graph is the same).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "bench/vs_pcl/pcl_chain.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/euclidean_cluster.hpp"
#include "kernels/ransac_plane.hpp"
#include "kernels/segmentation_chain.hpp"

namespace ob = orthoflow::bench;
namespace ok = orthoflow::kernels;

namespace {

class PclAgreement : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    auto r = orthoflow::formats::read_pcd(std::string(ORTHOFLOW_SHARED_DIR) + "/data/scenes/" +
                                          GetParam());
    ASSERT_TRUE(r) << r.error().to_string();
    cloud_ = std::move(*r);
    pcl_ = ob::run_pcl_chain(ob::to_pcl(cloud_));
    // Our filter + voxel stages on the same frame.
    const std::size_t n = cloud_.size();
    std::vector<std::uint8_t> mask(n);
    kept_ = {std::vector<float>(n), std::vector<float>(n), std::vector<float>(n)};
    ok::crop_box_mask(cloud_.points(), ok::SegmentationParams{}.roi, mask);
    const std::size_t kept =
        ok::compact_masked(cloud_.points(), mask, {kept_[0], kept_[1], kept_[2]}, {});
    for (auto& v : kept_) { v.resize(kept); }
    ok::VoxelGridScratch scratch(kept);
    vox_ = {std::vector<float>(kept), std::vector<float>(kept), std::vector<float>(kept)};
    auto vr = ok::voxel_grid({kept_[0], kept_[1], kept_[2]}, 0.005F, scratch,
                             {vox_[0], vox_[1], vox_[2]});
    ASSERT_TRUE(vr) << vr.error().to_string();
    for (auto& v : vox_) { v.resize(*vr); }
  }
  ok::PointCloud cloud_;
  ob::PclResult pcl_;
  std::array<std::vector<float>, 3> kept_, vox_;
};

TEST_P(PclAgreement, SameVoxelSetAndCentroids) {
  // Both order voxels by the same key (x fastest, z slowest, relative to the lowest voxel), so the
  // outputs correspond index by index. (Keys recomputed from PCL's float-summed centroids can cross
  // a voxel face when the points lie on it, as Kinect-quantised depths often do, so they are not
  // used.)
  EXPECT_EQ(kept_[0].size(), pcl_.cropped);
  ASSERT_EQ(vox_[0].size(), pcl_.voxels->size());
  const float inv = 1.0F / 0.005F;
  std::set<std::array<long, 3>> input_voxels;
  for (std::size_t i = 0; i < kept_[0].size(); ++i) {
    input_voxels.insert({long(std::floor(kept_[0][i] * inv)), long(std::floor(kept_[1][i] * inv)),
                         long(std::floor(kept_[2][i] * inv))});
  }
  EXPECT_EQ(input_voxels.size(), vox_[0].size());
  for (std::size_t i = 0; i < vox_[0].size(); ++i) {
    const auto& p = (*pcl_.voxels)[i];
    ASSERT_NEAR(vox_[0][i], p.x, 1e-5F) << "voxel " << i;
    ASSERT_NEAR(vox_[1][i], p.y, 1e-5F) << "voxel " << i;
    ASSERT_NEAR(vox_[2][i], p.z, 1e-5F) << "voxel " << i;
  }
}

TEST_P(PclAgreement, PlaneWithinOneDegreeAndFiveMillimetres) {
  std::vector<std::uint32_t> inliers(vox_[0].size());
  auto ours = ok::ransac_plane({vox_[0], vox_[1], vox_[2]}, {}, inliers);
  ASSERT_TRUE(ours) << ours.error().to_string();
  const auto& c = pcl_.plane.values;
  ASSERT_EQ(c.size(), 4U);
  const double len = std::sqrt(double(c[0]) * c[0] + double(c[1]) * c[1] + double(c[2]) * c[2]);
  double dot =
      (ours->plane.normal[0] * c[0] + ours->plane.normal[1] * c[1] + ours->plane.normal[2] * c[2]) /
      len;
  const double sign = dot < 0 ? -1.0 : 1.0;
  dot *= sign;
  EXPECT_LT(std::acos(std::min(1.0, dot)) * 180.0 / 3.14159265358979, 1.0);
  EXPECT_NEAR(double(ours->plane.d), sign * c[3] / len, 0.005);
  std::printf(
      "%s: ours n=(%.4f %.4f %.4f) d=%.4f inliers %zu | PCL (%.4f %.4f %.4f) d=%.4f inliers %zu\n",
      GetParam(), double(ours->plane.normal[0]), double(ours->plane.normal[1]),
      double(ours->plane.normal[2]), double(ours->plane.d), ours->inliers, sign * c[0] / len,
      sign * c[1] / len, sign * c[2] / len, sign * c[3] / len, pcl_.inliers);
}

TEST_P(PclAgreement, IdenticalClusterPartitionOnTheSamePoints) {
  const auto& objs = *pcl_.objects;
  std::vector<float> x, y, z;
  for (const auto& p : objs) { x.push_back(p.x), y.push_back(p.y), z.push_back(p.z); }
  ok::ClusterScratch scratch(x.size());
  std::vector<std::int32_t> labels(x.size());
  ok::ClusterParams params;  // 0.02 m, min 50: PCL's
  auto n = ok::euclidean_cluster({x, y, z}, {}, params, scratch, labels);
  ASSERT_TRUE(n) << n.error().to_string();
  std::set<std::vector<int>> ours_sets, pcl_sets;
  std::vector<std::vector<int>> ours(*n);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] >= 0) { ours[static_cast<std::size_t>(labels[i])].push_back(int(i)); }
  }
  for (auto& s : ours) { ours_sets.insert(s); }
  for (const auto& c : pcl_.clusters) {
    std::vector<int> s(c.indices.begin(), c.indices.end());
    std::sort(s.begin(), s.end());
    pcl_sets.insert(s);
  }
  EXPECT_EQ(ours_sets.size(), pcl_.clusters.size());
  EXPECT_TRUE(ours_sets == pcl_sets);
}

TEST_P(PclAgreement, OrganizedChainPlaneWithinOneDegreeAndFiveMillimetres) {
  // The organized chain fits the plane on a strided pixel sample
  // (SegmentationParams::organized_stride) instead of the voxels: the plane tolerance still
  // holds against PCL's voxel RANSAC.
  ok::SegmentationChain chain(cloud_.size(), ok::SegmentationParams{});
  auto seg = chain.run(cloud_.view());
  ASSERT_TRUE(seg) << seg.error().to_string();
  const auto& c = pcl_.plane.values;
  ASSERT_EQ(c.size(), 4U);
  const double len = std::sqrt(double(c[0]) * c[0] + double(c[1]) * c[1] + double(c[2]) * c[2]);
  const auto& n = seg->plane.plane.normal;
  double dot = (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / len;
  const double sign = dot < 0 ? -1.0 : 1.0;
  dot *= sign;
  EXPECT_LT(std::acos(std::min(1.0, dot)) * 180.0 / 3.14159265358979, 1.0);
  EXPECT_NEAR(double(seg->plane.plane.d), sign * c[3] / len, 0.005);
}

INSTANTIATE_TEST_SUITE_P(Mosd, PclAgreement,
                         ::testing::Values("test31.pcd", "test44.pcd", "test55.pcd"),
                         [](const auto& p) { return std::string(p.param).substr(0, 6); });

}  // namespace
