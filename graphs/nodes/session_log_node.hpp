#pragma once
/// @file
/// @brief The `session_log` sink node (stateful, ordered frames): every frame goes to a SessionLog
/// (graphs/services/session_log.hpp).
#include "engine/registry.hpp"
#include "graphs/services/session_log.hpp"

namespace orthoflow::graphs {

/// @brief Registers session_log, bound to @p log (which must outlive every graph built).
void add_session_log_node(engine::NodeRegistry& registry, SessionLog& log);

}  // namespace orthoflow::graphs
