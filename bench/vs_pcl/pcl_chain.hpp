#pragma once
// The PCL 1.13 tabletop chain of specs/BASELINES.md (benchmarks and tests only, never product
// code), timed per stage, plus helpers to turn our clouds into PCL clouds and PCL clusters into
// pixel labels.
#include <pcl/ModelCoefficients.h>
#include <pcl/common/centroid.h>
#include <pcl/filters/crop_box.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/filter.h>
#include <pcl/filters/project_inliers.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/extract_polygonal_prism_data.h>
#include <pcl/segmentation/sac_segmentation.h>
#include <pcl/surface/convex_hull.h>

#include <chrono>
#include <cmath>
#include <map>
#include <vector>

#include "kernels/point_cloud.hpp"

namespace orthoflow::bench {

using PclPoint = pcl::PointXYZRGBA;
using PclCloud = pcl::PointCloud<PclPoint>;

struct PclTimings {
  double filter = 0, voxel = 0, plane = 0, prism = 0, cluster = 0, pca = 0, total = 0;
};

struct PclResult {
  PclCloud::Ptr voxels{new PclCloud};
  PclCloud::Ptr objects{new PclCloud};  // prism output, what the clusters index
  pcl::ModelCoefficients plane;
  std::size_t inliers = 0;
  std::size_t cropped = 0;  // points after NaN removal + crop box
  std::vector<pcl::PointIndices> clusters;
  PclTimings t;
};

inline PclCloud::Ptr to_pcl(const kernels::PointCloud& c) {
  PclCloud::Ptr out(new PclCloud(c.width(), c.height()));
  for (std::size_t i = 0; i < c.size(); ++i) {
    auto& p = (*out)[i];
    p.x = c.x()[i], p.y = c.y()[i], p.z = c.z()[i];
    p.rgba = c.has(kernels::Field::RGB) ? c.rgb()[i] : 0U;
  }
  out->is_dense = false;
  return out;
}

/// Runs the chain with the BASELINES.md parameters (stages as in its table).
inline PclResult run_pcl_chain(const PclCloud::ConstPtr& input, float leaf = 0.005F,
                               float tau = 0.02F, int iters = 200, float tol = 0.02F,
                               int min_cluster = 50) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  PclResult r;
  const auto t0 = Clock::now();
  PclCloud::Ptr finite(new PclCloud), cropped(new PclCloud);
  pcl::Indices idx;
  pcl::removeNaNFromPointCloud(*input, *finite, idx);
  pcl::CropBox<PclPoint> crop;
  crop.setMin(Eigen::Vector4f(-1, -1, 0.3F, 1));
  crop.setMax(Eigen::Vector4f(1, 1, 2.0F, 1));
  crop.setInputCloud(finite);
  crop.filter(*cropped);
  r.cropped = cropped->size();
  const auto t1 = Clock::now();
  pcl::VoxelGrid<PclPoint> vg;
  vg.setLeafSize(leaf, leaf, leaf);
  vg.setInputCloud(cropped);
  vg.filter(*r.voxels);
  const auto t2 = Clock::now();
  pcl::SACSegmentation<PclPoint> seg;
  pcl::PointIndices::Ptr inliers(new pcl::PointIndices);
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_PLANE);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setDistanceThreshold(tau);
  seg.setMaxIterations(iters);
  seg.setInputCloud(r.voxels);
  seg.segment(*inliers, r.plane);
  r.inliers = inliers->indices.size();
  const auto t3 = Clock::now();
  PclCloud::Ptr projected(new PclCloud), hull(new PclCloud);
  pcl::ProjectInliers<PclPoint> proj;
  proj.setModelType(pcl::SACMODEL_PLANE);
  proj.setIndices(inliers);
  proj.setInputCloud(r.voxels);
  proj.setModelCoefficients(pcl::ModelCoefficients::ConstPtr(new pcl::ModelCoefficients(r.plane)));
  proj.filter(*projected);
  pcl::ConvexHull<PclPoint> chull;
  chull.setInputCloud(projected);
  chull.setDimension(2);
  chull.reconstruct(*hull);
  pcl::ExtractPolygonalPrismData<PclPoint> prism;
  prism.setInputCloud(r.voxels);
  prism.setInputPlanarHull(hull);
  prism.setHeightLimits(0.005, 0.5);
  pcl::PointIndices::Ptr above(new pcl::PointIndices);
  prism.segment(*above);
  pcl::ExtractIndices<PclPoint> extract;
  extract.setInputCloud(r.voxels);
  extract.setIndices(above);
  extract.filter(*r.objects);
  const auto t4 = Clock::now();
  pcl::search::KdTree<PclPoint>::Ptr tree(new pcl::search::KdTree<PclPoint>(false));
  pcl::EuclideanClusterExtraction<PclPoint> ec;
  ec.setClusterTolerance(tol);
  ec.setMinClusterSize(min_cluster);
  ec.setSearchMethod(tree);
  ec.setInputCloud(r.objects);
  ec.extract(r.clusters);
  const auto t5 = Clock::now();
  for (const auto& c : r.clusters) {
    Eigen::Matrix3f cov;
    Eigen::Vector4f centroid;
    pcl::computeMeanAndCovarianceMatrix(*r.objects, c, cov, centroid);
  }
  const auto t6 = Clock::now();
  r.t = {ms(t0, t1), ms(t1, t2), ms(t2, t3), ms(t3, t4), ms(t4, t5), ms(t5, t6), ms(t0, t6)};
  return r;
}

/// Per-pixel labels of the PCL clusters: a pixel takes the cluster of the voxel it falls in (the
/// voxel of a centroid is the voxel of its points), -1 elsewhere.
inline std::vector<std::int32_t> pcl_pixel_labels(const kernels::PointCloud& c, const PclResult& r,
                                                  float leaf) {
  const float inv = 1.0F / leaf;
  auto key = [inv](float x, float y, float z) {
    return std::array<long, 3>{long(std::floor(x * inv)), long(std::floor(y * inv)),
                               long(std::floor(z * inv))};
  };
  std::map<std::array<long, 3>, std::int32_t> voxel_cluster;
  for (std::size_t k = 0; k < r.clusters.size(); ++k) {
    for (const auto i : r.clusters[k].indices) {
      const auto& p = (*r.objects)[static_cast<std::size_t>(i)];
      voxel_cluster[key(p.x, p.y, p.z)] = static_cast<std::int32_t>(k);
    }
  }
  std::vector<std::int32_t> labels(c.size(), -1);
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!std::isfinite(c.z()[i])) { continue; }
    const auto it = voxel_cluster.find(key(c.x()[i], c.y()[i], c.z()[i]));
    if (it != voxel_cluster.end()) { labels[i] = it->second; }
  }
  return labels;
}

}  // namespace orthoflow::bench
