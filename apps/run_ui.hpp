#pragma once
/// @file
/// @brief `orthoflow run --ui [ADDR:]PORT [--ui-token-file FILE]`: the web view's server beside the
/// graph (ui/ui_server.hpp), over the run's learning service, objects hub and telemetry; and
/// `orthoflow ui --listen [ADDR:]PORT`, the same server in a process of its own over iceoryx
/// (ui/ipc_backend.hpp; add_ui_command in commands.hpp).
#include <cstdint>
#include <memory>
#include <string>

#include "engine/telemetry.hpp"
#include "graphs/nodes/objects_output.hpp"
#include "graphs/services/learning_service.hpp"

namespace orthoflow::apps {

/// @brief The running server and its backend; stops them when destroyed.
/// @pre destroyed before the learning service, the hub and the engine it was started with.
class RunUi {
 public:
  virtual ~RunUi() = default;
};

/// @brief Checks a --ui value ("" when fine, else the reason), for CLI11.
[[nodiscard]] std::string check_ui_listen(const std::string& value);

/// @brief Starts the server on @p listen (token from @p token_file when not empty) and prints its
/// URL, and the token when one is needed. The stream rate is capped at the graph's frame rate
/// (@p period_ns; 0 = unpaced) and at 30 Hz. With an iceoryx runtime in the process (the graph
/// publishes), the page's task buttons reach `orthoflow task run` for graph @p graph. Throws
/// CLI::RuntimeError when it cannot start.
[[nodiscard]] std::unique_ptr<RunUi> start_run_ui(const std::string& listen,
                                                  const std::string& token_file,
                                                  graphs::LearningService& learning,
                                                  graphs::ObjectsHub& hub,
                                                  const engine::GraphStats& stats,
                                                  std::int64_t period_ns, const std::string& graph);

}  // namespace orthoflow::apps
