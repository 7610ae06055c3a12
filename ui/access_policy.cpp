#include "ui/access_policy.hpp"

#include <algorithm>

namespace orthoflow::ui {

namespace {

bool listed(const std::vector<std::string>& values, std::string_view value) {
  return std::find(values.begin(), values.end(), value) != values.end();
}

// The token a request presents: the bearer header first, else the query parameter.
std::string_view presented_token(const RawRequest& request, bool& present) {
  const std::string_view header = find_header(request.headers, "Authorization", &present);
  if (present) {
    constexpr std::string_view BEARER = "Bearer ";
    return header.substr(0, BEARER.size()) == BEARER ? header.substr(BEARER.size())
                                                     : std::string_view{};
  }
  return query_value(request.query, "token", &present);
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
    const std::string_view token = presented_token(request, presented);
    if (!presented) return ApiError{401, "a bearer token is required"};
    if (!constant_time_equal(token, policy.token)) return ApiError{401, "wrong token"};
  }
  return std::nullopt;
}

}  // namespace orthoflow::ui
