#pragma once
/// @file
/// @brief The tabletop chain of specs/PIPELINE.md sections 2-4: the stages of
/// kernels/tabletop_stages.hpp and the candidate constraints of kernels/object_candidates.hpp run
/// back to back, with all memory sized once at construction (nothing allocates in run()). The
/// tabletop graph's preprocess, table and objects nodes run the same stage objects
/// (docs/SEGMENTATION.md):
/// - organized frame: strided pixel sample inside the ROI -> RANSAC plane (hypotheses scored on the
///   sample at twice the stride, refit on the sample) -> hull of the sample inliers -> prism (and
///   ROI) over the full-resolution pixels -> image-space clustering of those pixels -> footprint
///   merge. With organized_stride == 0, or a frame too narrow for the sample (MIN_SAMPLE_LINES),
///   the sample is replaced by the voxel grid of every kept pixel.
/// - unorganized cloud: ROI -> voxel grid -> RANSAC -> hull -> prism -> grid clustering, all on
/// voxels. leaf == 0 skips the voxel grid where it runs (RANSAC and hull then run on every kept
/// point).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "kernels/object_candidates.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::kernels {

/// @brief Wall time of each stage of the last run, milliseconds.
struct SegmentationTimings {
  double filter = 0, voxel = 0, plane = 0, prism = 0, cluster = 0, candidates = 0, total = 0;
};

/// @brief What run() found. Spans point into the chain and stay valid until the next run().
struct SegmentationResult {
  RansacPlane plane;
  PlaneCheck plane_check;                  ///< how sure the table stage is of the plane
  std::span<const ClusterStats> clusters;  ///< every cluster (after the footprint merge, when on)
  /// The clusters that pass C_size and C_edge (CandidateParams), in cluster order: the objects the
  /// tabletop graph hands to tracking.
  std::span<const ClusterStats> candidates;
  CandidateCounts candidate_counts;
  /// Per-point cluster id (-1 none): per input point on the organized chain, per voxel otherwise.
  std::span<const std::int32_t> labels;
  /// Per cluster: its index in candidates, or -1 (rejected by C_size / C_edge or over capacity).
  std::span<const std::int32_t> candidate_of;
  bool organized = false;
  SegmentationTimings timings;
  std::span<const double> hull_u, hull_v;  ///< the support polygon (make_plane_basis of the plane)
  std::size_t plane_sample = 0;            ///< the dense plane-input points (the verdict's share)
  std::uint32_t stride = 1;                ///< the object stage's budget: ObjectClusters::stride
  bool refined = true;                     ///< and ObjectClusters::refined
};

/// @brief Pre-sized tabletop segmentation. @note Not thread-safe; one instance per thread.
/// Deterministic: the same input and parameters give the same output.
class SegmentationChain {
 public:
  /// @brief Allocates every buffer for clouds of up to @p max_points points.
  SegmentationChain(std::size_t max_points, const SegmentationParams& params,
                    const CandidateParams& candidates = {});
  /// @brief Segments @p cloud. @pre cloud.points.size() <= max_points. Allocation-free. An
  /// organized cloud whose point count is not width x height is an error.
  [[nodiscard]] Result<SegmentationResult, SegmentationError> run(CloudView cloud);
  [[nodiscard]] const SegmentationParams& params() const noexcept { return params_; }
  [[nodiscard]] const CandidateParams& candidate_params() const noexcept {
    return candidate_params_;
  }

 private:
  SegmentationParams params_;
  CandidateParams candidate_params_;
  std::vector<float> px_, py_, pz_;  // plane input (dense sample, then the sparse one)
  std::vector<double> hull_u_, hull_v_;
  PlaneInputStage plane_input_;
  TableStage table_;
  ObjectStage objects_;
  std::vector<std::int32_t> slot_of_;
  std::vector<ClusterStats> candidates_;
};

}  // namespace orthoflow::kernels
