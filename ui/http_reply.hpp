#pragma once
/// @file
/// @brief The web view's HTTP answers: every one with the same safety headers (nothing cached,
/// sniffed or framed; scripts only from this origin) and `Connection: close`.
#include <string_view>

#include "ui/api_request.hpp"

struct mg_connection;

namespace orthoflow::ui {

/// @brief Writes a whole answer with @p extra headers (each ending in CRLF). @return @p status.
int reply(mg_connection* conn, int status, std::string_view type, std::string_view body,
          const char* extra = "");
/// @brief Writes @p error as its JSON body. @return its status.
int reply_error(mg_connection* conn, const ApiError& error, const char* extra = "");
/// @brief The headers a status needs (401: WWW-Authenticate, 429: Retry-After), else "".
const char* extra_headers_for(int status);

}  // namespace orthoflow::ui
