#pragma once
/// @file
/// @brief UiClient: the program side of the teaching API (docs/ui-api.openapi.yaml) for scripts,
/// `orthoflow teach --url ...` and bridges: one HTTP/1.1 request per call over civetweb's client
/// (the response is parsed by civetweb, never by hand), the bearer token when one is given, a
/// response-time limit, and a bounded body. Plain http only (the server speaks no TLS).
#include <cstdint>
#include <string>
#include <string_view>

#include "core/result.hpp"

namespace orthoflow::ui {

/// @brief Where a running orthoflow's UI listens, and how to talk to it.
struct ClientTarget {
  std::string host;        ///< IPv4 address or name, as in the URL
  std::uint16_t port = 0;  ///< 1-65535
  std::string token;       ///< bearer token ("" = none: enough on loopback)
  int timeout_ms = 5000;   ///< for the response (the server answers an action within 3 s)
};

/// @brief "http://HOST:PORT" with an optional trailing "/". Errors name what is wrong (another
/// scheme, a path, a missing or out-of-range port, userinfo).
[[nodiscard]] Result<ClientTarget, std::string> parse_ui_url(std::string_view url);

/// @brief A server's answer: the HTTP status and the body (JSON for every /api/ route).
struct ClientReply {
  int status = 0;
  std::string body;
};

/// @brief Largest response body read (a state document with 64 objects and 200 categories is far
/// below); a longer one is an error, not a truncated answer.
inline constexpr std::size_t MAX_REPLY_BYTES = 4U << 20U;

/// @brief Sends @p method @p path (with @p json_body as application/json when not empty) and reads
/// the answer. Errors: cannot connect, no answer within the timeout, a body beyond MAX_REPLY_BYTES
/// or shorter than its Content-Length. A 4xx or 5xx is a reply, not an error.
[[nodiscard]] Result<ClientReply, std::string> send_ui_request(const ClientTarget& target,
                                                               std::string_view method,
                                                               std::string_view path,
                                                               std::string_view json_body);

}  // namespace orthoflow::ui
