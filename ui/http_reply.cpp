// HTTP answers of the web view (http_reply.hpp).
#include "ui/http_reply.hpp"

#include <civetweb.h>

#include "ui/ui_json.hpp"

namespace orthoflow::ui {

namespace {
// Headers every answer carries: nothing cached, nothing sniffed or framed, scripts only from here.
constexpr const char* COMMON_HEADERS =
    "Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\n"
    "Referrer-Policy: no-referrer\r\n"
    "Content-Security-Policy: default-src 'self'; connect-src 'self'; frame-ancestors 'none'\r\n";

}  // namespace

int reply(mg_connection* conn, int status, std::string_view type, std::string_view body,
          const char* extra) {
  mg_printf(conn,
            "HTTP/1.1 %d %s\r\nContent-Type: %.*s\r\nContent-Length: %zu\r\n%s%s"
            "Connection: close\r\n\r\n",
            status, mg_get_response_code_text(conn, status), static_cast<int>(type.size()),
            type.data(), body.size(), COMMON_HEADERS, extra);
  mg_write(conn, body.data(), body.size());
  return status;
}

int reply_error(mg_connection* conn, const ApiError& error, const char* extra) {
  return reply(conn, error.status, "application/json", error_json(error), extra);
}

const char* extra_headers_for(int status) {
  if (status == 401) return "WWW-Authenticate: Bearer\r\n";
  if (status == 429) return "Retry-After: 1\r\n";
  return "";
}

}  // namespace orthoflow::ui
