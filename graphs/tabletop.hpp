#pragma once
/// @file
/// @brief Every node kind of the tabletop graph in one registry: the engine's generic kinds (join,
/// ...) and IPC kinds (ipc_subscribe, ipc_publish) plus sources, segmentation, track, describe, recognise and session_log. recognise and
/// session_log are bound to a LearningService and a SessionLog that outlive the graphs built.
#include "engine/registry.hpp"
#include "graphs/learning_service.hpp"
#include "graphs/session_log.hpp"

namespace orthoflow::graphs {

/// @brief A registry with the generic and tabletop kinds.
[[nodiscard]] engine::NodeRegistry make_tabletop_registry(LearningService& learning, SessionLog& log);

}  // namespace orthoflow::graphs
