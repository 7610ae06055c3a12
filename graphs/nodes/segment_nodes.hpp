#pragma once
/// @file
/// @brief The three segmentation kinds of the tabletop graph (specs/PIPELINE.md sections 2-4), each
/// one stage of kernels/tabletop_stages.hpp: `preprocess` (ROI + strided sample or voxel grid: the
/// plane input), `table` (RANSAC plane + support polygon) and `objects` (prism + Euclidean clusters
/// + footprint merge + candidate constraints C_size and C_edge + gather). Each is stateful (it owns
/// its stage, sized once at start-up) and writes its results into the frame block; parameters:
/// graphs/nodes/segment_params.hpp.
#include "engine/registry.hpp"
#include "graphs/frame/frame_block.hpp"
#include "graphs/nodes/labels_writer.hpp"
#include "kernels/tabletop_stages.hpp"

namespace orthoflow::graphs {

/// @brief Registers preprocess, table and objects.
/// @param labels `--labels-out`: the objects nodes hand each frame's per-point labels to it (null:
/// none).
void add_segment_nodes(engine::NodeRegistry& registry, LabelsWriter* labels = nullptr);

/// @brief The plane input preprocess left in @p block (views into voxels()).
[[nodiscard]] kernels::PlaneInput plane_input(const FrameBlock& block) noexcept;

}  // namespace orthoflow::graphs
