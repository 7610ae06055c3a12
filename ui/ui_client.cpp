#include "ui/ui_client.hpp"

#include <civetweb.h>

#include <array>
#include <charconv>
#include <memory>

namespace orthoflow::ui {

Result<ClientTarget, std::string> parse_ui_url(std::string_view url) {
  constexpr std::string_view SCHEME = "http://";
  if (url.substr(0, SCHEME.size()) != SCHEME) {
    return err("--url '" + std::string(url) + "': must start with http:// (the UI speaks no TLS)");
  }
  std::string_view rest = url.substr(SCHEME.size());
  if (!rest.empty() && rest.back() == '/') rest.remove_suffix(1);
  if (rest.find_first_of("/?#") != std::string_view::npos)
    return err("--url '" + std::string(url) + "': give only http://HOST:PORT, no path");
  if (rest.find('@') != std::string_view::npos)
    return err("--url '" + std::string(url) + "': no user in the URL (use --token-file)");
  const std::size_t colon = rest.rfind(':');
  if (colon == std::string_view::npos || colon == 0)
    return err("--url '" + std::string(url) + "': needs HOST:PORT");
  const std::string_view port_text = rest.substr(colon + 1);
  unsigned port = 0;
  const auto [end, ec] =
      std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (ec != std::errc{} || end != port_text.data() + port_text.size() || port == 0 || port > 65535U)
    return err("--url '" + std::string(url) + "': port must be 1-65535");
  ClientTarget target;
  target.host = std::string(rest.substr(0, colon));
  target.port = static_cast<std::uint16_t>(port);
  return target;
}

namespace {

struct Closer {
  void operator()(mg_connection* c) const noexcept { mg_close_connection(c); }
};

// civetweb's global state, held for the client's lifetime (reference counted by civetweb).
struct Library {
  Library() { mg_init_library(MG_FEATURES_DEFAULT); }
  ~Library() { mg_exit_library(); }
  Library(const Library&) = delete;
  Library& operator=(const Library&) = delete;
};

}  // namespace

Result<ClientReply, std::string> send_ui_request(const ClientTarget& target,
                                                 std::string_view method, std::string_view path,
                                                 std::string_view json_body) {
  const Library library;
  std::array<char, 256> error{};
  const std::string where = "http://" + target.host + ":" + std::to_string(target.port);
  std::unique_ptr<mg_connection, Closer> conn(
      mg_connect_client(target.host.c_str(), target.port, 0, error.data(), error.size()));
  if (!conn) return err("cannot connect to " + where + ": " + std::string(error.data()));
  std::string head = std::string(method) + " " + std::string(path) +
                     " HTTP/1.1\r\nHost: " + target.host + ":" + std::to_string(target.port) +
                     "\r\nConnection: close\r\nAccept: application/json\r\n";
  if (!target.token.empty()) head += "Authorization: Bearer " + target.token + "\r\n";
  if (!json_body.empty()) {
    head +=
        "Content-Type: application/json\r\nContent-Length: " + std::to_string(json_body.size()) +
        "\r\n";
  }
  head += "\r\n";
  const bool sent =
      mg_write(conn.get(), head.data(), head.size()) == static_cast<int>(head.size()) &&
      (json_body.empty() || mg_write(conn.get(), json_body.data(), json_body.size()) ==
                                static_cast<int>(json_body.size()));
  if (!sent) return err("could not send the request to " + where);
  if (mg_get_response(conn.get(), error.data(), error.size(), target.timeout_ms) < 0) {
    return err("no answer from " + where + " within " + std::to_string(target.timeout_ms) +
               " ms: " + std::string(error.data()));
  }
  const mg_response_info* info = mg_get_response_info(conn.get());
  if (info == nullptr) return err("no response from " + where);
  ClientReply reply;
  reply.status = info->status_code;
  const long long expected = info->content_length;
  if (expected > static_cast<long long>(MAX_REPLY_BYTES))
    return err("answer from " + where + " is larger than " + std::to_string(MAX_REPLY_BYTES) +
               " bytes");
  std::array<char, 16384> chunk{};
  for (;;) {
    const int n = mg_read(conn.get(), chunk.data(), chunk.size());
    if (n <= 0) break;
    if (reply.body.size() + static_cast<std::size_t>(n) > MAX_REPLY_BYTES)
      return err("answer from " + where + " is larger than " + std::to_string(MAX_REPLY_BYTES) +
                 " bytes");
    reply.body.append(chunk.data(), static_cast<std::size_t>(n));
  }
  if (expected >= 0 && reply.body.size() != static_cast<std::size_t>(expected)) {
    return err("answer from " + where + " cut short: " + std::to_string(reply.body.size()) +
               " of " + std::to_string(expected) + " bytes");
  }
  return reply;
}

}  // namespace orthoflow::ui
