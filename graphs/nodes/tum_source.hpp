#pragma once
/// @file
/// @brief `tum_source`: the depth images of a folder in the TUM RGB-D benchmark's layout
/// (formats/tum_rgbd.hpp: associate.txt or depth.txt, 16-bit PNGs at 5000 per metre),
/// back-projected with the pinhole the benchmark recommends (fx = fy = 525, cx = 319.5,
/// cy = 239.5; parameters), at the recorded pace (`pace: recorded`) or as fast as the graph takes
/// frames (`pace: max`). Reading runs ahead on a decoder thread. A TUM folder has no "up" the
/// product reads: its frames carry none (the table node's `up` parameter can give one).
#include "engine/registry.hpp"

namespace orthoflow::graphs {

/// @brief Registers tum_source.
void add_tum_source(engine::NodeRegistry& registry);

}  // namespace orthoflow::graphs
