#pragma once
/// @file
/// @brief The web view server's settings: where it listens (`--ui [ADDR:]PORT`), its bearer token
/// (generated, or read from `--ui-token-file`), limits. A plain struct, validated once.
#include <cstdint>
#include <string>
#include <string_view>

#include "core/result.hpp"
#include "ui/rate_limiter.hpp"

namespace orthoflow::ui {

/// @brief Bytes of randomness in a generated token (printed as 2 hex digits each).
inline constexpr std::size_t TOKEN_BYTES = 24;

/// @brief Settings of one UiServer.
struct UiServerConfig {
  std::string address = "127.0.0.1";  ///< IPv4 address to bind (loopback by default)
  std::uint16_t port = 0;             ///< 0: an ephemeral port (tests)
  std::string token;  ///< required beyond loopback; UiServer::start generates one when empty
  RateLimit rate;     ///< per client address
  double max_stream_hz = 30.0;      ///< the WebSocket rate cap: the graph's frame rate, at most 30
  int ack_timeout_ms = 3000;        ///< how long an action waits for its LearningAck
  unsigned threads = 4;             ///< civetweb worker threads (HTTP requests and WebSockets)
  unsigned max_stream_clients = 8;  ///< WebSocket streams at once
};

/// @brief Parses "PORT" or "ADDR:PORT" (ADDR an IPv4 address or "localhost"; PORT 0..65535, 0 = a
/// free port the system picks, which UiServer::url() shows) into @p config. Errors name the
/// problem.
[[nodiscard]] Result<void, std::string> parse_listen(std::string_view text, UiServerConfig& config);

/// @brief A fresh token: TOKEN_BYTES from std::random_device, in hex.
[[nodiscard]] std::string generate_token();

/// @brief Writes a generated @p token to a new file only this user can read (mode 0600, created
/// exclusively in the temporary directory) and returns its path, so that the token itself is never
/// printed.
[[nodiscard]] Result<std::string, std::string> write_private_token(const std::string& token);

/// @brief The token in @p path (first line, surrounding white space removed; at least 16
/// characters of printable ASCII). Errors name the file and the problem.
/// The file must be a regular file of at most 4 KiB (core/regular_file.hpp: a FIFO or a device is
/// refused at once, never waited on).
[[nodiscard]] Result<std::string, std::string> read_token_file(const std::string& path);
/// @brief The token in a token file's @p text (read_token_file's rule); errors start with @p what.
[[nodiscard]] Result<std::string, std::string> token_from_text(const std::string& text,
                                                               const std::string& what);

}  // namespace orthoflow::ui
