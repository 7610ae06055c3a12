#pragma once
/// @file
/// @brief Every node kind of the tabletop graph in one registry: the engine's generic kinds (join,
/// ...) and IPC kinds (ipc_subscribe, ipc_publish) plus sources, the robot-body filter,
/// segmentation, track, describe,
/// recognise, objects_output and session_log. recognise, objects_output and session_log are bound
/// to a LearningService, an ObjectsHub and a SessionLog that outlive the graphs built.
#include "engine/registry.hpp"
#include "graphs/nodes/labels_writer.hpp"
#include "graphs/nodes/objects_output.hpp"
#include "graphs/services/arm_state_feed.hpp"
#include "graphs/services/learning_service.hpp"
#include "graphs/services/session_log.hpp"

namespace orthoflow::graphs {

/// @brief A registry with the generic and tabletop kinds.
/// @param objects the in-process consumers of every frame's objects (null: none)
/// @param labels where the objects nodes write each frame's per-point labels (null: nowhere)
/// @param arm_state the in-process arm state that `body_filter` nodes with `state: channel` read
/// (null: none; `state: ipc` needs none)
[[nodiscard]] engine::NodeRegistry make_tabletop_registry(LearningService& learning,
                                                          SessionLog& log,
                                                          ObjectsHub* objects = nullptr,
                                                          LabelsWriter* labels = nullptr,
                                                          ArmStateFeed* arm_state = nullptr);

}  // namespace orthoflow::graphs
