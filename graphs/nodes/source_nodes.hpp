#pragma once
/// @file
/// @brief Frame sources of the tabletop graph. Both emit FrameBlocks with the raw organized frame
/// written in place, stamps, and (when known) the ground truth of the frame.
/// - `synthetic_source`: the synthetic Kinect v1 generator playing the embedded session (objects=0)
///   or a random scripted sequence (objects=N); allocation-free after the first frame.
/// - `pcd_source`: the .pcd files of a folder in name order (reading a file allocates; this source
///   is for replay and evaluation, not for the allocation-free live path).
/// The engine paces both at the graph period (`period_ms`; 0 = as fast as the graph takes frames).
#include <filesystem>

#include "engine/registry.hpp"
#include "graphs/nodes/decode_ahead.hpp"

namespace orthoflow::graphs {

/// @brief pcd_source's decoding step: formats::read_pcd of @p file into @p slot (ok, cloud or
/// error). Runs on the DecodeAhead thread; allocates.
void read_pcd_into(const std::filesystem::path& file, DecodeAhead::Slot& slot);

/// @brief Registers synthetic_source and pcd_source.
void add_source_nodes(engine::NodeRegistry& registry);

}  // namespace orthoflow::graphs
