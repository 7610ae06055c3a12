#pragma once
/// @file
/// @brief The three segmentation kinds of the tabletop graph (specs/PIPELINE.md sections 2-4):
/// `preprocess` (NaN + ROI + voxel grid), `table` (RANSAC plane + support polygon) and `objects`
/// (prism + Euclidean clusters + candidate constraints C_size and C_edge). Each is stateful (it owns
/// its kernel scratch, sized once at start-up) and writes its results into the frame block.
#include "engine/registry.hpp"

namespace orthoflow::graphs {

/// @brief Registers preprocess, table and objects.
void add_segment_nodes(engine::NodeRegistry& registry);

}  // namespace orthoflow::graphs
