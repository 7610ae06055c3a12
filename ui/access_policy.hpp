#pragma once
/// @file
/// @brief Who may talk to the web view's server, as a pure check of one request (fuzzed with the
/// decoder). Three rules, in this order:
///   1. Host (loopback binding only): the Host header names the loopback address the server listens
///      on ("127.0.0.1:P", "localhost:P"), so a page of another site that a DNS name rebinds to
///      127.0.0.1 is refused (403).
///   2. Origin: a request with an Origin header is served only when it is the server's own origin
///      (403 otherwise); a cross-site fetch or WebSocket from another page always carries one.
///   3. Token (when the server listens beyond loopback): "Authorization: Bearer <token>", or
///      "?token=<token>" where a browser cannot set a header (the page's first load, the WebSocket
///      upgrade), or the page's cookie (token_cookie: set on the page that was loaded with the
///      token, so that the browser's requests for the page's script and style carry it too);
///      compared in constant time (401 otherwise).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ui/api_request.hpp"

namespace orthoflow::ui {

/// @brief What a request is checked against; made once by the server after it bound its port.
struct AccessPolicy {
  bool loopback = true;              ///< listening on a loopback address only: rule 1 applies
  std::vector<std::string> hosts;    ///< rule 1: accepted Host values ("127.0.0.1:8080", ...)
  std::vector<std::string> origins;  ///< rule 2: accepted Origin values ("http://127.0.0.1:8080")
  bool host_is_origin = false;       ///< rule 2 also accepts "http://" + Host (wildcard address)
  std::string token;                 ///< rule 3 when not empty
  std::string cookie_name;  ///< rule 3's cookie: "orthoflow_token_<port>" (cookies ignore ports)
};

/// @brief The policy of a server listening on @p address (IPv4 text) port @p port with @p token
/// ("" = none). @pre a token is given when @p address is not loopback.
[[nodiscard]] AccessPolicy make_access_policy(std::string_view address, unsigned port,
                                              std::string token);

/// @brief The Set-Cookie header line (with CRLF) that hands the page's browser the token, or ""
/// when the policy has no token or the token holds a character a cookie value cannot (RFC 6265
/// cookie-octet: no space, '"', ',', ';' or '\\'; generated tokens are hex). HttpOnly: no script
/// reads it; SameSite=Strict: no other site's page makes the browser send it.
[[nodiscard]] std::string token_cookie(const AccessPolicy& policy);

/// @brief Whether @p address is an IPv4 loopback address (127.0.0.0/8) or "localhost".
[[nodiscard]] bool is_loopback_address(std::string_view address) noexcept;

/// @brief Equal contents, in time that depends only on the lengths (no early exit on a mismatch).
[[nodiscard]] bool constant_time_equal(std::string_view a, std::string_view b) noexcept;

/// @brief The first rule @p request breaks (status 401 or 403 and a sentence), or nothing.
/// @note Pure.
[[nodiscard]] std::optional<ApiError> check_access(const AccessPolicy& policy,
                                                   const RawRequest& request);

}  // namespace orthoflow::ui
