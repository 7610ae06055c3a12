#pragma once
/// @file
/// @brief The settings of the tabletop chain (kernels/tabletop_stages.hpp, which includes this
/// file): SegmentationParams, one plain struct with the PCL baseline's defaults, and the crowded
/// mode's ClusterMode and CreaseParams. Plain data: validated by the stages that take it.
#include <cstdint>

#include "kernels/crop.hpp"
#include "kernels/euclidean_cluster.hpp"
#include "kernels/organized_normals.hpp"
#include "kernels/ransac_plane.hpp"

namespace orthoflow::kernels {

/// @brief How the object stage splits the points above the table into objects.
enum class ClusterMode : std::uint8_t {
  EUCLIDEAN,  ///< connected components under the distance tolerance (PCL's rule; the cheapest)
  /// Organized frames: the same components, cut along concave creases of the surface (where a box
  /// stands on a box, or a mug leans on a bottle), found from per-pixel normals; the crease pixels
  /// then rejoin the piece beside them. The footprint merge joins a piece to the one below it only
  /// when it does not rise above it (CreaseParams::max_rise). Unorganized clouds: EUCLIDEAN.
  CROWDED,
};

/// @brief The crowded mode's crease test (docs/SEGMENTATION.md, "Crowded scenes").
struct CreaseParams {
  NormalParams normals{};
  /// A pixel lies on a crease when the normals this many pixels to either side of it (along its
  /// row or its column) differ by more than min_angle_deg and the surface between them is concave.
  std::uint32_t gap = 6;
  float min_angle_deg = 35.0F;
  /// Crowded mode: the footprint merge joins two overlapping pieces only if the one with the
  /// smaller footprint rises at most this far above the other's top (a bowl's inside within its
  /// outside), not a box lying on another. Metres.
  float max_rise = 0.01F;
  /// Crowded mode: a piece whose lowest point is higher than this above the table and that lies
  /// neither on nor under another piece (a handle cut off its mug) joins the piece with the nearest
  /// footprint within the clustering tolerance. Metres (above the prism's h_min to mean anything).
  float stand_height = 0.015F;
  /// Rounds of re-attaching crease pixels to the piece beside them (each reaches pixel_radius
  /// further into the crease band).
  std::uint32_t attach_rounds = 4;
  /// Crowded mode, occlusion join (kernels/occlusion_join.cpp): two pieces with tops within
  /// occlusion_top of each other are one object seen on both sides of a nearer one when at least
  /// occlusion_rows image rows (and 30 % of the shorter piece's rows) run piece, occluder at least
  /// occluder_gap nearer, piece. 0 rows: off. Metres.
  std::uint32_t occlusion_rows = 8;
  float occluder_gap = 0.02F;
  float occlusion_top = 0.015F;
  /// Crowded mode, neck split (kernels/neck_split.cpp), last: a piece whose footprint on the table
  /// is two or more round cores joined by a neck (two cans of one height touching, whose tops
  /// meet where no crease parts them) is cut at the neck. The footprint is drawn on a grid of
  /// neck_cell (0: off); a core is at least neck_core in radius, a neck at most neck_ratio of the
  /// smaller core's radius wide (half-width over radius), and only round parts are cut: each
  /// part's footprint at most neck_round times the disc of its core's radius. Metres.
  float neck_cell = 0.005F;
  float neck_core = 0.015F;
  float neck_ratio = 0.5F;
  float neck_round = 1.5F;
};

/// @brief Chain settings; defaults are the PCL baseline's (specs/BASELINES.md).
/// @brief The object stage's work budget, fixed at start (issue 50 item 3). A frame beyond it is
/// degraded in this order, deterministically, and ObjectClusters says how:
/// 1. more than max_points prism pixels (organized path): only every s-th pixel of every s-th row
///    is clustered, s = 2, 3 or 4, the smallest that fits (at most 4); the cluster window and the
///    cluster sizes in points scale with it, so the same metric neighbourhood links pixels;
/// 2. more than max_refine_clusters clusters: the crowded refinements (footprint merge, occlusion
///    join, neck split) are skipped;
/// 3. more candidates than the caller keeps: the nearest to the sensor are kept
///    (kernels::select_candidates with nearest_first), the farthest dropped.
/// 0 turns a limit off.
struct ObjectBudget {
  std::size_t max_points = 0;
  std::size_t max_refine_clusters = 0;
};

struct SegmentationParams {
  AxisBox roi{{-1.0F, -1.0F, 0.3F}, {1.0F, 1.0F, 2.0F}};
  float leaf = 0.005F;  ///< 0: no voxel grid
  RansacParams ransac{};
  float h_min = 0.005F;
  float h_max = 0.5F;
  ClusterParams cluster{};
  bool use_organized = true;  ///< organized input: image-space clustering of full-resolution pixels
  /// Organized input only: the plane refit and the hull run on every organized_stride-th pixel of
  /// every organized_stride-th row inside the ROI (pixel_subsample), RANSAC scores its hypotheses
  /// on the sample at twice that stride (when it has >= 500 points), and leaf is not used; 0: the
  /// voxel grid of leaf over every kept pixel, as for unorganized input.
  std::uint32_t organized_stride = 4;
  /// Footprint merge: clusters whose footprints on the table (boxes in the plane's u, v) overlap by
  /// at least this share of the smaller one are one object in pieces (a bowl's near and far walls).
  /// 0: off (the PCL baseline has no such step); the tabletop graph uses 0.3.
  float merge_overlap = 0.0F;
  ClusterMode cluster_mode = ClusterMode::EUCLIDEAN;
  CreaseParams crease{};
  ObjectBudget budget{};
};

}  // namespace orthoflow::kernels
