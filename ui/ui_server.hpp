#pragma once
/// @file
/// @brief UiServer: the web view and its JSON API over HTTP and WebSocket, on civetweb, inside the
/// process (`orthoflow run --ui [ADDR:]PORT`). A thin, strict face over a UiBackend (STYLE rule
/// 19): every request is rate-limited per client, checked against the AccessPolicy (Host, Origin,
/// bearer token beyond loopback), read with a body limit, decoded by decode_request(), then served:
/// the state, an action through the learning channel, or an embedded asset. No file system access.
/// Routes and documents: ui/api_request.hpp, ui/ui_json.hpp; ui/README.md.
#include <cstdint>
#include <memory>
#include <string>

#include "core/result.hpp"
#include "ui/access_policy.hpp"
#include "ui/rate_limiter.hpp"
#include "ui/server_config.hpp"
#include "ui/ui_backend.hpp"
#include "ui/ui_event_stream.hpp"

struct mg_context;
struct mg_connection;

namespace orthoflow::ui {

/// @note Thread-safe; civetweb's worker threads call into it. @pre @p backend outlives it.
class UiServer {
 public:
  /// @brief Binds and starts serving. A token is generated when none is configured and the address
  /// is not loopback. Errors: civetweb without WebSocket support, the address or port in use.
  [[nodiscard]] static Result<std::unique_ptr<UiServer>, std::string> start(UiServerConfig config,
                                                                            UiBackend& backend);
  /// @brief Stops serving (closes every connection, joins civetweb's threads).
  ~UiServer();
  UiServer(const UiServer&) = delete;
  UiServer& operator=(const UiServer&) = delete;

  [[nodiscard]] std::uint16_t port() const noexcept { return port_; }
  /// @brief The bearer token ("" when none is required).
  [[nodiscard]] const std::string& token() const noexcept { return policy_.token; }
  /// @brief "http://ADDR:PORT/" (with "?token=..." when a token is required): what to open.
  [[nodiscard]] std::string url() const;
  [[nodiscard]] const EventStream& stream() const noexcept { return *stream_; }

  // civetweb's callbacks (public for the C trampolines in ui_server.cpp).
  int handle_http(mg_connection* conn);
  int ws_connect(const mg_connection* conn);
  void ws_ready(mg_connection* conn);
  void ws_close(const mg_connection* conn);

 private:
  UiServer(UiServerConfig config, UiBackend& backend);
  int serve(mg_connection* conn, const ApiRequest& request);
  int act(mg_connection* conn, const ApiRequest& request);
  int act_task(mg_connection* conn, const ApiRequest& request);
  int act_arm_stop(mg_connection* conn);

  UiServerConfig config_;
  UiBackend& backend_;
  AccessPolicy policy_;
  std::string cookie_;  ///< the page's Set-Cookie line (token_cookie), "" without a token
  RateLimiter limiter_;
  std::unique_ptr<EventStream> stream_;
  mg_context* ctx_ = nullptr;
  std::uint16_t port_ = 0;
};

}  // namespace orthoflow::ui
