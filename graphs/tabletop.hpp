#pragma once
/// @file
/// @brief Every node kind of the tabletop graph in one registry: the engine's generic kinds (join,
/// ...) and IPC kinds (ipc_subscribe, ipc_publish) plus sources, segmentation, track, describe,
/// recognise, objects_output and session_log. recognise, objects_output and session_log are bound
/// to a LearningService, an ObjectsHub and a SessionLog that outlive the graphs built.
#include "engine/registry.hpp"
#include "graphs/labels_writer.hpp"
#include "graphs/learning_service.hpp"
#include "graphs/objects_output.hpp"
#include "graphs/session_log.hpp"

namespace orthoflow::graphs {

/// @brief A registry with the generic and tabletop kinds.
/// @param objects the in-process consumers of every frame's objects (null: none)
/// @param labels where the objects nodes write each frame's per-point labels (null: nowhere)
[[nodiscard]] engine::NodeRegistry make_tabletop_registry(LearningService& learning,
                                                          SessionLog& log,
                                                          ObjectsHub* objects = nullptr,
                                                          LabelsWriter* labels = nullptr);

}  // namespace orthoflow::graphs
