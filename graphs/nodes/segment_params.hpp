#pragma once
/// @file
/// @brief The parameters of the preprocess, table and objects node kinds, parsed into the one
/// kernels::SegmentationParams / CandidateParams pair the chain takes, so that a graph file and
/// `orthoflow segment --graph FILE` mean the same segmentation (start-up only: these allocate).
#include <array>
#include <optional>
#include <string>

#include "core/result.hpp"
#include "engine/graph.hpp"
#include "engine/params.hpp"
#include "kernels/segmentation_chain.hpp"
#include "kernels/table_verdict.hpp"

namespace orthoflow::graphs {

/// @brief The table node's verdict (kernels/table_verdict.hpp) and where "up" comes from when a
/// frame does not carry it.
struct TableSettings {
  kernels::TableVerdictParams verdict{};
  /// `up: "x,y,z"`: the camera's configured pose says where up is in the sensor frame (used only
  /// for frames that carry no reading of their own); nullopt: nothing configured.
  std::optional<std::array<float, 3>> up;
  /// Frames the last accepted table is kept through when a frame's plane fails the verdict (a
  /// hand or an arm in front of the table for a moment). 0: no hysteresis.
  std::uint32_t hold_frames = 2;
  /// A sensor's "up" older than this is not trusted (a camera whose accelerometer reads stopped,
  /// or one that was moved since): the frame falls back to the configured up, else none, and says
  /// so (`up_stale_ms`). The Kinect driver reads its accelerometer every 100 ms.
  std::uint32_t max_up_age_ms = 1000;
};

/// @brief The segmentation of the tabletop graph: the stage parameters, the candidate
/// constraints and the table verdict.
struct TabletopSegmentation {
  kernels::SegmentationParams stages = defaults();
  kernels::CandidateParams candidates{};
  TableSettings table{};
  /// @brief The node kinds' defaults (where they differ from the chain's PCL-baseline ones: the
  /// footprint merge is on, clusters need 50 points with a 2-pixel window).
  [[nodiscard]] static kernels::SegmentationParams defaults() noexcept;
};

/// @brief preprocess: roi_min_x..roi_max_z (m), leaf (m, 0 = off), organized_stride (0 = voxel
/// grid).
[[nodiscard]] Result<void, std::string> parse_preprocess_params(const engine::ParamMap& params,
                                                                kernels::SegmentationParams& out);
/// @brief table: tau (m), iterations, confidence, seed; the verdict's max_tilt_deg, min_height,
/// max_height (m), min_share, min_area (m^2), hold_frames, up ("x,y,z", normalised) and
/// max_up_age_ms.
[[nodiscard]] Result<void, std::string> parse_table_params(const engine::ParamMap& params,
                                                           TabletopSegmentation& out);
/// @brief objects: h_min, h_max, tolerance, min_points, max_points, pixel_radius, merge_overlap and
/// the candidate constraints min_size, max_size, edge_margin.
[[nodiscard]] Result<void, std::string> parse_objects_params(const engine::ParamMap& params,
                                                             TabletopSegmentation& out);

/// @brief The segmentation a graph file runs: the parameters of its preprocess, table and objects
/// nodes (each kind at most once; a kind that is absent keeps its defaults). Errors name the node.
[[nodiscard]] Result<TabletopSegmentation, std::string> segmentation_of_graph(
    const engine::GraphSpec& spec);

}  // namespace orthoflow::graphs
