#pragma once
/// @file
/// @brief Decoding one HTTP request of the web view's API into a typed request, as a pure function
/// (no I/O, no global state), so that it is unit-tested and fuzzed (tests/fuzz/fuzz_ui_request.cpp)
/// apart from the server. Routes:
///   GET  /api/state                      the latest objects, the memory, events, latency
///   GET  /api/events[?hz=N]              WebSocket stream of the same state at N Hz
///   POST /api/teach   {"track": T, "label": "L"}
///   POST /api/correct {"track": T, "label": "L"}
///   POST /api/ask     {"track": T}
///   POST /api/forget  {"label": "L"}
///   POST /api/undo    {}                 take back the most recent teach / correct
///   GET  any other path                  an embedded asset (ui/ui_assets.hpp)
/// Actions are POST only (no state-changing GET), with a JSON body of at most MAX_BODY_BYTES.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "graphs/channels/task_payloads.hpp"

namespace orthoflow::ui {

/// @brief Largest request body accepted (413 beyond).
inline constexpr std::size_t MAX_BODY_BYTES = 16 * 1024;
/// @brief Stream rate when ?hz= is absent.
inline constexpr double DEFAULT_STREAM_HZ = 10.0;

/// @brief One header as received (name compared case-insensitively).
struct HttpHeader {
  std::string_view name;
  std::string_view value;
};

/// @brief A request as the server received it. Views into the server's buffers.
struct RawRequest {
  std::string_view method;  ///< "GET", "POST", ...
  std::string_view path;    ///< URL-decoded path, without the query
  std::string_view query;   ///< after '?', without it ("" when none)
  std::span<const HttpHeader> headers;
  std::string_view body;
};

/// @brief A refused request: the HTTP status and a sentence for the client.
struct ApiError {
  int status = 400;
  std::string message;
};

/// @brief A decoded request.
struct ApiRequest {
  enum class Kind : std::uint8_t {
    STATE,
    EVENTS,
    TEACH,
    CORRECT,
    ASK,
    FORGET,
    UNDO,
    ASSET,
    CAMERA,
    TASK_START,  ///< POST /api/task/start: start a table task (ui/task_link.hpp)
    TASK_STOP,   ///< POST /api/task/stop
    ARM_STOP,    ///< POST /api/arm/stop: halt the arm in place and latch (docs/SAFETY.md)
  };
  Kind kind = Kind::STATE;
  std::uint32_t track = 0;        ///< TEACH, CORRECT, ASK: >= 1
  core::Text label;               ///< TEACH, CORRECT, FORGET: checked with core::check_label
  double hz = DEFAULT_STREAM_HZ;  ///< EVENTS: requested rate (> 0; the server clamps it)
  bool camera = false;     ///< EVENTS: ?camera=1, the client shows the camera image: keep it coming
  std::string_view asset;  ///< ASSET: the path to look up
  graphs::TaskCommand task;  ///< TASK_START, TASK_STOP: the command (categories checked as labels)
};

/// @brief "state", "events", "teach", ...
[[nodiscard]] std::string_view to_string(ApiRequest::Kind kind) noexcept;

/// @brief The value of header @p name (case-insensitive), or "" when absent; @p present says which.
[[nodiscard]] std::string_view find_header(std::span<const HttpHeader> headers,
                                           std::string_view name, bool* present = nullptr) noexcept;

/// @brief The value of query parameter @p key ("" when absent). No percent-decoding: the
/// parameters this API reads (hz, token) are plain ASCII.
[[nodiscard]] std::string_view query_value(std::string_view query, std::string_view key,
                                           bool* present = nullptr) noexcept;

/// @brief Decodes @p request. Errors: 404 unknown /api/ path, 405 wrong method, 413 body too large,
/// 415 an action without a JSON content type, 400 malformed JSON, missing / extra / mistyped field,
/// bad track id, bad label (core/label_text.hpp), bad ?hz=. Never throws, never crashes.
/// @note Pure: the result depends only on @p request.
[[nodiscard]] Result<ApiRequest, ApiError> decode_request(const RawRequest& request);

}  // namespace orthoflow::ui
