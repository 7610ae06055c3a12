// spin_images (kernels/spin_image.hpp) against PCL's pcl::SpinImageEstimation on the same points,
// normals (PCL's NormalEstimation), keypoints (voxel_keypoints) and parameters: every bin within
// 1e-5 (PCL accumulates in double in its kd-tree's neighbour order, ours in point order; both
// divide by the sum). PCL's NaN image (every neighbour outside the cylinder) is our all-zeros one.
// PCL is a test reference only.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <pcl/features/normal_3d.h>
#include <pcl/features/spin_image.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/features/impl/spin_image.hpp>

#include "bench/vs_pcl/mug_view.hpp"
#include "kernels/spin_image.hpp"

namespace ok = orthoflow::kernels;

namespace {

template <int N>
void compare_with_pcl(std::uint32_t width, float support, float angle_cos) {
  ASSERT_EQ(static_cast<std::size_t>(N), ok::spin_image_bins(width));
  const auto cloud =
      orthoflow::bench::mug_view(width * 31 + static_cast<std::uint32_t>(support * 1000));
  auto normals = std::make_shared<pcl::PointCloud<pcl::Normal>>();
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setInputCloud(cloud);
  ne.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  ne.setRadiusSearch(0.015);
  ne.compute(*normals);

  const std::size_t n = cloud->size();
  std::vector<float> x(n), y(n), z(n), nx(n), ny(n), nz(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = (*cloud)[i].x;
    y[i] = (*cloud)[i].y;
    z[i] = (*cloud)[i].z;
    nx[i] = (*normals)[i].normal_x;
    ny[i] = (*normals)[i].normal_y;
    nz[i] = (*normals)[i].normal_z;
  }
  const ok::PointsView points{x, y, z}, nv{nx, ny, nz};
  ok::VoxelGridScratch scratch(n);
  std::vector<float> cx(n), cy(n), cz(n);
  std::vector<std::uint32_t> voxel_keys(n);
  auto found = ok::voxel_keypoints(points, 0.01F, scratch, {cx, cy, cz}, voxel_keys);
  ASSERT_TRUE(found.has_value());
  // Keypoints with a normal (PCL takes a NaN axis as cos = 1; ours gives no image).
  auto keys = std::make_shared<pcl::Indices>();
  for (std::size_t k = 0; k < found.value(); ++k) {
    const std::uint32_t i = voxel_keys[k];
    if (std::isfinite(nx[i]) && std::isfinite(ny[i]) && std::isfinite(nz[i]))
      keys->push_back(static_cast<int>(i));
  }
  ASSERT_GT(keys->size(), 40U);

  pcl::SpinImageEstimation<pcl::PointXYZ, pcl::Normal, pcl::Histogram<N>> si(width, angle_cos, 0);
  si.setInputCloud(cloud);
  si.setInputNormals(normals);
  si.setIndices(keys);
  si.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  si.setRadiusSearch(static_cast<double>(support));
  pcl::PointCloud<pcl::Histogram<N>> theirs;
  si.compute(theirs);
  ASSERT_EQ(theirs.size(), keys->size());

  std::vector<std::uint32_t> ours_keys(keys->begin(), keys->end());
  std::vector<float> ours(ours_keys.size() * N);
  auto r = ok::spin_images(points, nv, ours_keys, {width, support, angle_cos}, ours);
  ASSERT_TRUE(r.has_value()) << r.error().to_string();
  std::size_t pcl_described = 0;
  for (std::size_t k = 0; k < ours_keys.size(); ++k) {
    const bool nan = std::isnan(theirs[k].histogram[0]);
    pcl_described += nan ? 0U : 1U;
    for (int b = 0; b < N; ++b) {
      const float want = nan ? 0.0F : theirs[k].histogram[b];
      ASSERT_NEAR(ours[k * N + static_cast<std::size_t>(b)], want, 1e-5F)
          << "keypoint " << ours_keys[k] << " bin " << b << " width " << width;
    }
  }
  EXPECT_EQ(r.value(), pcl_described);
  EXPECT_GT(pcl_described, keys->size() / 2);
}

TEST(SpinImageVsPcl, ThesisBagOfWordsDefaults) { compare_with_pcl<45>(4, 0.05F, 0.0F); }
TEST(SpinImageVsPcl, ThesisSetsOfSpinImages) { compare_with_pcl<153>(8, 0.10F, 0.0F); }
TEST(SpinImageVsPcl, WithASupportAngle) { compare_with_pcl<45>(4, 0.05F, 0.5F); }

}  // namespace
