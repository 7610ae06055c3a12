#pragma once
/// @file
/// @brief The `track` kind (stateful, needs ordered frames: it associates clusters with tracks and
/// splits the frame into one message per object) and the `describe` kind (stateless, runs objects
/// in parallel: object reference frame and GOOD descriptor, specs/PIPELINE.md section 6).
#include "engine/registry.hpp"

namespace orthoflow::graphs {

/// @brief Registers track and describe.
void add_track_describe_nodes(engine::NodeRegistry& registry);

}  // namespace orthoflow::graphs
