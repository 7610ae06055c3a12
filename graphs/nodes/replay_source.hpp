#pragma once
/// @file
/// @brief `replay_source`: the depth records of a fakenect recording (`orthoflow kinect record`,
/// or libfreenect's `fakenect-record`), converted with the recording's device.json through the
/// same conversion code as the live camera, at the recorded pace (`pace: recorded`) or as fast as
/// the graph takes frames (`pace: max`). Reading runs ahead on a decoder thread.
#include "engine/registry.hpp"

namespace orthoflow::graphs {

/// @brief Registers replay_source.
void add_replay_source(engine::NodeRegistry& registry);

}  // namespace orthoflow::graphs
