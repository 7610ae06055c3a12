#pragma once
/// @file
/// @brief The web view's JSON documents: the state (GET /api/state and every WebSocket message), an
/// action's answer and an error, and the HTTP status each learning outcome maps to.
#include <string>

#include <nlohmann/json.hpp>

#include "ui/api_request.hpp"
#include "ui/ui_backend.hpp"

namespace orthoflow::ui {

/// @brief The state document: {"frame", "age_ms", "durable", "objects": [{"track", "label" (null =
/// Unknown), "score", "centroid", "bbox_min", "bbox_max", "points", "moving", "described"}],
/// "memory": [{"label", "views", "last_taught_ms"}], "events": [...], "telemetry": {...}}.
/// A score that is not finite (before any lesson) is null. "tasks": whether task commands can be
/// sent; "task": the task process's newest state {"state", "task", "answer", "move", "moves",
/// "done", "phase", "message", "age_ms"}, or null.
[[nodiscard]] std::string state_json(const UiSnapshot& snapshot);

/// @brief A task process's state: {"state", "task", "answer", "move", "moves", "done", "phase",
/// "message"} (what `orthoflow task status --json` prints too).
[[nodiscard]] nlohmann::json task_status_json(const graphs::TaskStatus& status);

/// @brief The answer to a task command: {"ok", "action", "state", "task", "answer", "move",
/// "moves", "done", "phase", "message"}.
[[nodiscard]] std::string task_answer_json(const graphs::TaskCommand& command,
                                           const graphs::TaskStatus& answer);

/// @brief The HTTP status of an action's answer: 200 for stored / learned / answered; 404
/// no_such_track, unknown_label; 400 bad_label; 409 not_described; 422 rejected; 500 write_failed;
/// 503 busy or a full queue; 504 no acknowledgement in time.
[[nodiscard]] int http_status(const UiAnswer& answer) noexcept;

/// @brief {"ok", "action", "outcome", "track", "label", "views", "frame", "durable"} and for an ask
/// "answer" (null = Unknown), "nearest" and "score"; "error" when not ok.
[[nodiscard]] std::string answer_json(const UiAction& action, const UiAnswer& answer, bool durable);

/// @brief {"error": message, "status": status}.
[[nodiscard]] std::string error_json(const ApiError& error);

}  // namespace orthoflow::ui
