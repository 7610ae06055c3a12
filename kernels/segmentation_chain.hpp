#pragma once
/// @file
/// @brief The tabletop chain of specs/PIPELINE.md sections 2-4 composed from the kernels, with all its
/// memory sized once at construction (nothing allocates in run()). Chains (see docs/SEGMENTATION.md):
/// - organized frame: strided pixel sample inside the ROI -> RANSAC plane (hypotheses scored on the
///   sample at twice the stride, refit on the sample) -> hull of the sample inliers -> prism (and ROI) over the full-resolution pixels -> image-space clustering of those
///   pixels. With organized_stride == 0 the sample is replaced by the voxel grid of every kept pixel.
/// - unorganized cloud: ROI -> voxel grid -> RANSAC -> hull -> prism -> grid clustering, all on voxels.
/// leaf == 0 skips the voxel grid where it runs (RANSAC and hull then run on every kept point).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "kernels/cluster_stats.hpp"
#include "kernels/crop.hpp"
#include "kernels/euclidean_cluster.hpp"
#include "kernels/ransac_plane.hpp"
#include "kernels/voxel_grid.hpp"

namespace orthoflow::kernels {

/// @brief Chain settings; defaults are the PCL baseline's (specs/BASELINES.md).
struct SegmentationParams {
  AxisBox roi{{-1.0F, -1.0F, 0.3F}, {1.0F, 1.0F, 2.0F}};
  float leaf = 0.005F;  ///< 0: no voxel grid
  RansacParams ransac{};
  float h_min = 0.005F;
  float h_max = 0.5F;
  ClusterParams cluster{};
  bool use_organized = true;  ///< organized input: image-space clustering of full-resolution pixels
  /// Organized input only: the plane refit and the hull run on every organized_stride-th pixel of every
  /// organized_stride-th row inside the ROI (pixel_subsample), RANSAC scores its hypotheses on the sample
  /// at twice that stride (when it has >= 500 points), and leaf is not used; 0: the voxel grid of leaf
  /// over every kept pixel, as for unorganized input.
  std::uint32_t organized_stride = 4;
};

/// @brief Wall time of each stage of the last run, milliseconds.
struct SegmentationTimings {
  double filter = 0, voxel = 0, plane = 0, prism = 0, cluster = 0, total = 0;
};

/// @brief What run() found. Spans point into the chain and stay valid until the next run().
struct SegmentationResult {
  RansacPlane plane;
  std::span<const ClusterStats> objects;
  /// Per-point cluster id (-1 none): per input point on the organized chain, per voxel otherwise.
  std::span<const std::int32_t> labels;
  bool organized = false;
  SegmentationTimings timings;
};

/// @brief Why run() failed (the message names the stage).
struct SegmentationError {
  std::string message;
  [[nodiscard]] const std::string& to_string() const noexcept { return message; }
};

/// @brief Pre-sized tabletop segmentation. @note Not thread-safe; one instance per thread.
/// Deterministic: the same input and parameters give the same output.
class SegmentationChain {
 public:
  /// @brief Allocates every buffer for clouds of up to @p max_points points.
  SegmentationChain(std::size_t max_points, const SegmentationParams& params);
  /// @brief Segments @p cloud. @pre cloud.points.size() <= max_points. Allocation-free. An organized
  /// cloud whose point count is not width x height is an error.
  [[nodiscard]] Result<SegmentationResult, SegmentationError> run(CloudView cloud);
  [[nodiscard]] const SegmentationParams& params() const noexcept { return params_; }

 private:
  Result<std::size_t, SegmentationError> filter_and_voxel(CloudView cloud, bool organized, SegmentationTimings& t);
  Result<std::size_t, SegmentationError> fit_plane_on_sample(bool organized);
  Result<std::size_t, SegmentationError> hull_of_inliers(std::size_t inliers);
  Result<std::size_t, SegmentationError> objects(CloudView cloud, bool organized, SegmentationTimings& t);

  SegmentationParams params_;
  std::size_t max_points_;
  std::vector<std::uint8_t> mask_;
  std::vector<float> kx_, ky_, kz_;  // kept points
  std::vector<float> vx_, vy_, vz_;  // voxel centroids
  std::vector<std::uint32_t> inliers_, hull_scratch_, hull_idx_;
  std::vector<double> pu_, pv_, hull_u_, hull_v_;
  std::vector<float> heights_;
  std::vector<std::int32_t> labels_;
  std::vector<ClusterMoments> moments_;
  std::vector<ClusterStats> stats_;
  VoxelGridScratch voxel_scratch_;
  ClusterScratch cluster_scratch_;
  PointsView plane_points_{};
  PointsView sparse_points_{};  // organized strided path: RANSAC's hypotheses are scored on these
  static constexpr std::size_t MIN_SPARSE_POINTS = 500;  // below: RANSAC on the full sample
  RansacPlane plane_{};
};

}  // namespace orthoflow::kernels
