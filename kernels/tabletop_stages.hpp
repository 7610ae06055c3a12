#pragma once
/// @file
/// @brief The stages of the tabletop chain (specs/PIPELINE.md sections 2-4), each a stage object
/// that owns its scratch (sized once at construction) and writes its results into memory the caller
/// hands it. The chain (kernels/segmentation_chain.hpp) runs them back to back; the graph's
/// preprocess, table and objects nodes run the same objects, one per node (STYLE rule 15: one
/// implementation, the product runs it). Nothing here allocates after construction, starts a thread
/// or does I/O.
///
/// - PlaneInputStage: organized frame: strided pixel sample inside the ROI (the plane-fit input)
/// and the
///   sample at twice the stride (RANSAC scores its hypotheses there); unorganized cloud, or stride
///   0: ROI crop then voxel grid (or every kept point when leaf == 0).
/// - TableStage: RANSAC plane (refit on the dense sample), convex hull of the inliers.
/// - ObjectStage: prism (hull, height range and ROI) over the full-resolution pixels (organized) or
/// the
///   plane input (unorganized), Euclidean clusters, the footprint merge, per-cluster statistics.
///
/// The settings (SegmentationParams, ClusterMode, CreaseParams) are in
/// kernels/segmentation_params.hpp, included here.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "kernels/cluster_stats.hpp"
#include "kernels/convex_hull.hpp"
#include "kernels/crop.hpp"
#include "kernels/detail/neck_scratch.hpp"
#include "kernels/euclidean_cluster.hpp"
#include "kernels/organized_normals.hpp"
#include "kernels/ransac_plane.hpp"
#include "kernels/segmentation_params.hpp"
#include "kernels/voxel_grid.hpp"

namespace orthoflow::kernels {

/// @brief Why a stage failed. Plain data: building one on the frame path never allocates. @p cause
/// keeps the kernel's own reason (RansacError / VoxelGridError / ClusterError code) and @p value
/// its number.
struct SegmentationError {
  enum class Code : std::uint8_t {
    CLOUD_TOO_LARGE,     ///< more points than the stage was sized for (value: the point count)
    NOT_WIDTH_X_HEIGHT,  ///< an organized cloud whose point count is not width x height (value: the
                         ///< count)
    OUTPUT_TOO_SMALL,    ///< the caller's output span cannot hold the plane input (value: points
                         ///< needed)
    VOXEL_GRID_FAILED,   ///< cause: VoxelGridError::Code
    NO_PLANE,            ///< RANSAC found none; cause: RansacError::Code
    FEW_SAMPLE_INLIERS,  ///< the plane has fewer than 3 inliers on the dense sample
    DEGENERATE_HULL,     ///< the inliers' hull has fewer than 3 vertices
    HULL_TOO_LARGE,      ///< the hull has more vertices than the caller's hull span holds (value:
                         ///< count)
    CLUSTERING_FAILED,   ///< cause: ClusterError::Code
    /// fewer than 3 finite points inside the ROI, too few for a plane (value: the points inside;
    /// finite: the finite points of the whole cloud; roi: the box)
    FEW_POINTS_IN_ROI,
  };
  Code code = Code::NO_PLANE;
  std::uint8_t cause = 0;
  double value = 0.0;
  std::uint32_t width = 0, height = 0;  ///< NOT_WIDTH_X_HEIGHT: the image size the cloud claims
  std::uint64_t finite = 0;             ///< FEW_POINTS_IN_ROI: the finite points of the cloud
  AxisBox roi{};                        ///< FEW_POINTS_IN_ROI: the region of interest
  /// @brief The full message: stage, reason and the kernel's own message. Allocates: off the frame
  /// path.
  [[nodiscard]] std::string to_string() const;
};

/// @brief Short name of a code, e.g. "NO_PLANE". Never allocates.
[[nodiscard]] std::string_view to_string(SegmentationError::Code code) noexcept;

/// @brief Plane-fit input of one frame, in the caller's output span.
struct PlaneInput {
  PointsView dense;  ///< the points RANSAC refits on and the hull is built from
  PointsView
      sparse;  ///< organized strided path: RANSAC scores its hypotheses on these (may be empty)
  std::size_t kept =
      0;  ///< finite points inside the ROI that fed it (organized strided: the dense sample)
  double filter_ms = 0.0, voxel_ms = 0.0;  ///< wall time of the ROI / sample and of the voxel grid
};

/// @brief True when the chain takes its organized path for @p cloud under @p params.
[[nodiscard]] bool takes_organized_path(CloudView cloud, const SegmentationParams& params) noexcept;

/// @brief Fewest sample columns and rows the organized strided path needs: one column of a depth
/// image lies in a plane through the camera, so a sample of one or two columns (or rows) cannot
/// tell the table from that plane. A narrower organized frame takes the voxel grid of every kept
/// pixel, as an unorganized cloud does (the prism and the clustering still run on its pixels).
inline constexpr std::uint32_t MIN_SAMPLE_LINES = 3;
/// @brief Pieces the occlusion join considers (the first ones; a cluttered frame has more).
inline constexpr std::size_t MAX_OCCLUSION_PIECES = 64;

/// @brief The number of sample lines pixel_subsample takes across @p extent pixels at @p stride.
/// @pre stride >= 1.
[[nodiscard]] constexpr std::uint32_t sample_lines(std::uint32_t extent,
                                                   std::uint32_t stride) noexcept {
  const std::uint32_t first = stride / 2;
  return extent > first ? (extent - first - 1) / stride + 1 : 0;
}

/// @brief True when the organized strided path samples @p cloud (organized_stride > 0 and at least
/// MIN_SAMPLE_LINES sample columns and rows); false: the voxel grid of every kept pixel.
[[nodiscard]] bool takes_strided_sample(CloudView cloud, const SegmentationParams& params) noexcept;

/// @brief Stage 1: ROI, strided sample or voxel grid. Fewer than 3 finite points inside the ROI is
/// FEW_POINTS_IN_ROI; a strided sample of fewer than 3 points falls back to every kept pixel.
/// @note Not thread-safe; one instance per thread.
class PlaneInputStage {
 public:
  /// @brief Allocates its scratch for clouds of up to @p max_points points.
  explicit PlaneInputStage(std::size_t max_points);
  /// @brief Writes the plane input of @p cloud to the front of @p out (dense sample, then the
  /// sparse one).
  /// @pre out.size() >= max_points, or at least the sample bounds of an organized cloud that
  /// takes_strided_sample(). Allocation-free.
  [[nodiscard]] Result<PlaneInput, SegmentationError> run(CloudView cloud,
                                                          const SegmentationParams& params,
                                                          PointsSpan out) noexcept;

 private:
  [[nodiscard]] Result<PlaneInput, SegmentationError> every_kept_point(
      CloudView cloud, const SegmentationParams& params, PointsSpan out) noexcept;
  std::size_t max_points_;
  std::vector<std::uint8_t> mask_;
  std::vector<float> kx_, ky_, kz_;  // kept points before the voxel grid
  VoxelGridScratch voxel_scratch_;
};

/// @brief How sure the table stage is of its plane (docs/SEGMENTATION.md, "The table plane").
struct PlaneCheck {
  float near_share = 0.0F;  ///< share of the dense sample's plane inliers within 1 cm of the plane
  float rms_m = 0.0F;       ///< RMS distance of those 1 cm inliers
  /// The first plane was another level parallel to the table (the floor below it, or the top of an
  /// object standing on it) and the table stage took the table instead.
  bool switched = false;
};

/// @brief The table a frame stands on: plane, inlier count and support polygon (in the caller's
/// spans).
struct TableModel {
  RansacPlane plane;
  std::span<const double> hull_u, hull_v;  ///< counter-clockwise, in make_plane_basis(plane.plane)
  PlaneCheck check{};
};

/// @brief Stage 2: RANSAC plane, refined on the dense sample (least squares on the inliers within
/// tau, then tau / 2, then tau / 4), checked against a second plane among the points off it (a
/// parallel level more than h_max above the plane means the plane was the floor; one less than
/// h_max below it means the plane was an object's top: the stage takes that level instead), and
/// the convex hull of its inliers. @note Not thread-safe.
class TableStage {
 public:
  explicit TableStage(std::size_t max_points);
  /// @brief Fits the table to @p input; the hull goes to the front of @p hull_u / @p hull_v.
  /// @pre input.dense.size() <= max_points. Allocation-free. Deterministic (seeded RANSAC).
  [[nodiscard]] Result<TableModel, SegmentationError> run(const PlaneInput& input,
                                                          const SegmentationParams& params,
                                                          std::span<double> hull_u,
                                                          std::span<double> hull_v) noexcept;

 private:
  static constexpr std::size_t MIN_SPARSE_POINTS = 500;  // below: RANSAC on the dense sample
  /// Refines @p plane on @p dense (refits at tau, tau / 2, tau / 4); @return its tau inliers.
  std::size_t refine(PointsView dense, float tau, Plane& plane) noexcept;
  /// The level the table is, given the first plane (PlaneCheck::switched).
  [[nodiscard]] bool other_level(PointsView dense, const SegmentationParams& p,
                                 RansacPlane& plane) noexcept;
  std::vector<std::uint32_t> inliers_, hull_scratch_, hull_idx_;
  std::vector<double> pu_, pv_;
  std::vector<float> ox_, oy_, oz_;  // the dense sample off the first plane
};

/// @brief What the object stage found. Spans point into the stage and stay valid until its next
/// run().
struct ObjectClusters {
  PointsView
      target;  ///< the points labelled: the full-resolution pixels (organized) or the plane input
  std::span<const std::int32_t> labels;  ///< per target point: cluster id or -1
  /// Ascending superset of the clustered indices (all when empty). At stride > 1 the prism pixels
  /// thinned out are not members but are labelled too, from the nearest clustered pixel of their
  /// stride cell's corners within the cluster tolerance, so labels stay dense for the pixel-level
  /// evaluation and the labels output while statistics and descriptors use the members.
  std::span<const std::uint32_t> members;
  std::span<const ClusterStats> clusters;  ///< after the footprint merge
  std::size_t prism_points = 0;            ///< points inside the prism (before any thinning)
  double prism_ms = 0.0,
         cluster_ms = 0.0;   ///< wall time of the prism and of clusters + merge + statistics
  std::uint32_t stride = 1;  ///< budget step 1: every stride-th pixel and row clustered (1: all)
  bool refined = true;       ///< false: budget step 2 skipped the crowded refinements
};

/// @brief Stage 3: prism, clusters, footprint merge, statistics. @note Not thread-safe.
class ObjectStage {
 public:
  /// @brief Sized for clouds of up to @p max_points points and clusters of at least @p
  /// min_cluster_size.
  ObjectStage(std::size_t max_points, std::uint32_t min_cluster_size);
  /// @brief Objects above @p table. @p plane_input is the stage-1 output (the target of an
  /// unorganized cloud).
  /// @pre the cloud passed stage 1 with the same @p params. Allocation-free. Deterministic.
  [[nodiscard]] Result<ObjectClusters, SegmentationError> run(
      CloudView cloud, const PlaneInput& plane_input, const TableModel& table,
      const SegmentationParams& params) noexcept;

 private:
  std::size_t merge_footprints(PointsView target, std::span<const std::uint32_t> members,
                               const PlaneBasis& basis, std::size_t clusters, float overlap,
                               float max_rise, float stand_height, float attach_gap) noexcept;
  /// Crowded mode, organized: joins the pieces an occluder cut apart (CreaseParams::occlusion_*);
  /// @return the cluster count after. kernels/occlusion_join.cpp.
  std::size_t join_occluded(CloudView cloud, std::span<const std::uint32_t> members,
                            std::size_t clusters, const CreaseParams& p) noexcept;
  /// Crowded mode: cuts pieces whose footprint is cores joined by necks (CreaseParams::neck_*);
  /// pieces the occlusion join made are left whole. @return the cluster count after.
  /// kernels/neck_split.cpp.
  std::size_t split_necks(PointsView target, std::span<const std::uint32_t> members,
                          const PlaneBasis& basis, std::size_t clusters, std::uint32_t min_size,
                          const CreaseParams& p) noexcept;
  /// Crowded mode, organized: clusters of the prism pixels off the creases, then the crease pixels
  /// re-attached; members_ lists every prism pixel. kernels/crease_split.cpp.
  [[nodiscard]] Result<std::size_t, ClusterError> cluster_crowded(
      CloudView cloud, const SegmentationParams& p) noexcept;
  std::vector<float> heights_;
  std::vector<std::uint8_t> mask_;
  std::vector<std::uint8_t> prism_mask_;  // the prism before the budget's thinning
  std::vector<std::int32_t> labels_;
  std::vector<ClusterMoments> moments_;
  std::vector<ClusterStats> stats_;
  ClusterScratch cluster_scratch_;
  std::vector<std::array<double, 7>>
      footprints_;  // u, v box, highest, lowest height, lies on/under
  std::vector<std::int32_t> root_, new_id_;
  std::vector<float> nx_, ny_, nz_;           // crowded mode: per-pixel normals
  std::vector<std::uint8_t> off_crease_;      // crowded mode: prism pixels off the creases
  std::vector<std::uint8_t> round_;           // crowded mode: attach round of each pixel
  std::vector<std::uint32_t> members_;        // crowded mode: every prism pixel, ascending
  std::vector<std::uint32_t> pending_;        // crowded mode: crease pixels not yet attached
  std::vector<std::uint16_t> votes_;          // occlusion join: rows per piece pair
  std::vector<std::array<float, 4>> pieces_;  // occlusion join: top, bottom, first row, last row
  std::vector<std::uint8_t> joined_;          // occlusion join: the cluster joined pieces
  detail::NeckScratch neck_;                  // neck split
};

}  // namespace orthoflow::kernels
