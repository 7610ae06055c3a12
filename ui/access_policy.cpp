#include "ui/access_policy.hpp"

#include <algorithm>

namespace orthoflow::ui {

namespace {

bool listed(const std::vector<std::string>& values, std::string_view value) {
  return std::find(values.begin(), values.end(), value) != values.end();
}

// The value of cookie @p name in a Cookie header ("a=1; b=2"), or "" when absent.
std::string_view cookie_value(std::string_view cookies, std::string_view name, bool& present) {
  while (!cookies.empty()) {
    const std::size_t end = cookies.find(';');
    std::string_view pair = cookies.substr(0, end);
    while (!pair.empty() && pair.front() == ' ') pair.remove_prefix(1);
    const std::size_t eq = pair.find('=');
    if (eq != std::string_view::npos && pair.substr(0, eq) == name) {
      present = true;
      return pair.substr(eq + 1);
    }
    cookies = end == std::string_view::npos ? std::string_view{} : cookies.substr(end + 1);
  }
  present = false;
  return {};
}

// The token a request presents: the bearer header first, else the query parameter, else the
// page's cookie.
std::string_view presented_token(const AccessPolicy& policy, const RawRequest& request,
                                 bool& present) {
  const std::string_view header = find_header(request.headers, "Authorization", &present);
  if (present) {
    constexpr std::string_view BEARER = "Bearer ";
    return header.substr(0, BEARER.size()) == BEARER ? header.substr(BEARER.size())
                                                     : std::string_view{};
  }
  const std::string_view query = query_value(request.query, "token", &present);
  if (present) return query;
  bool has_cookies = false;
  const std::string_view cookies = find_header(request.headers, "Cookie", &has_cookies);
  if (!has_cookies || policy.cookie_name.empty()) return {};
  return cookie_value(cookies, policy.cookie_name, present);
}

bool is_cookie_octet(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u >= 0x21 && u <= 0x7E && c != '"' && c != ',' && c != ';' && c != '\\';
}

}  // namespace

bool is_loopback_address(std::string_view address) noexcept {
  return address == "localhost" || address.substr(0, 4) == "127.";
}

bool constant_time_equal(std::string_view a, std::string_view b) noexcept {
  // Every byte of the longer text is visited whatever matches, so the time tells only the length.
  const std::size_t n = std::max(a.size(), b.size());
  unsigned diff = a.size() == b.size() ? 0U : 1U;
  for (std::size_t i = 0; i < n; ++i) {
    const auto x = i < a.size() ? static_cast<unsigned char>(a[i]) : 0U;
    const auto y = i < b.size() ? static_cast<unsigned char>(b[i]) : 0U;
    diff |= x ^ y;
  }
  return diff == 0;
}

AccessPolicy make_access_policy(std::string_view address, unsigned port, std::string token) {
  AccessPolicy policy;
  const std::string p = std::to_string(port);
  policy.loopback = is_loopback_address(address);
  policy.token = std::move(token);
  policy.cookie_name = "orthoflow_token_" + p;
  if (policy.loopback) {
    for (const std::string_view name : {std::string_view("localhost"), address}) {
      policy.hosts.push_back(std::string(name) + ":" + p);
      policy.origins.push_back("http://" + std::string(name) + ":" + p);
    }
  } else if (address == "0.0.0.0") {
    policy.host_is_origin = true;  // any interface: its own origin is whatever name reached it
  } else {
    policy.origins.push_back("http://" + std::string(address) + ":" + p);
  }
  return policy;
}

std::string token_cookie(const AccessPolicy& policy) {
  if (policy.token.empty() ||
      !std::all_of(policy.token.begin(), policy.token.end(), is_cookie_octet))
    return {};
  return "Set-Cookie: " + policy.cookie_name + "=" + policy.token +
         "; Path=/; HttpOnly; SameSite=Strict\r\n";
}

std::optional<ApiError> check_access(const AccessPolicy& policy, const RawRequest& request) {
  const std::string_view host = find_header(request.headers, "Host");
  if (policy.loopback && !listed(policy.hosts, host))
    return ApiError{403, "the Host header does not name this server"};
  bool has_origin = false;
  const std::string_view origin = find_header(request.headers, "Origin", &has_origin);
  if (has_origin && !listed(policy.origins, origin) &&
      !(policy.host_is_origin && !host.empty() && origin == "http://" + std::string(host)))
    return ApiError{403, "cross-origin requests are refused"};
  if (!policy.token.empty()) {
    bool presented = false;
    const std::string_view token = presented_token(policy, request, presented);
    if (!presented) return ApiError{401, "a bearer token is required"};
    if (!constant_time_equal(token, policy.token)) return ApiError{401, "wrong token"};
  }
  return std::nullopt;
}

}  // namespace orthoflow::ui
