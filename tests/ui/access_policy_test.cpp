// The pure security checks of the web view: Host / Origin / bearer token (ui/access_policy.hpp),
// the per-client token bucket (ui/rate_limiter.hpp), listen address and token parsing
// (ui/server_config.hpp) and the embedded asset table (ui/ui_assets.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <vector>

#include "ui/access_policy.hpp"
#include "ui/rate_limiter.hpp"
#include "ui/server_config.hpp"
#include "ui/ui_assets.hpp"

namespace orthoflow::ui {
namespace {

std::optional<ApiError> access(const AccessPolicy& p, const std::vector<HttpHeader>& headers,
                               std::string_view query = "") {
  return check_access(p, RawRequest{"GET", "/api/state", query, headers, ""});
}

int status(const std::optional<ApiError>& e) { return e ? e->status : 200; }

TEST(AccessPolicy, NonLoopbackNeedsTheRightToken) {
  const std::string token = "0123456789abcdef0123456789abcdef";
  const AccessPolicy p = make_access_policy("192.0.2.10", 8080, token);
  EXPECT_FALSE(p.loopback);
  EXPECT_EQ(status(access(p, {{"Host", "192.0.2.10:8080"}})), 401);
  EXPECT_EQ(access(p, {{"Host", "192.0.2.10:8080"}})->message, "a bearer token is required");
  EXPECT_EQ(status(access(p, {{"Authorization", "Bearer wrong"}})), 401);
  EXPECT_EQ(status(access(p, {{"Authorization", "Bearer " + token + "x"}})), 401);
  EXPECT_EQ(status(access(p, {{"Authorization", "Basic " + token}})), 401);
  EXPECT_EQ(status(access(p, {{"Authorization", "Bearer " + token}})), 200);
  EXPECT_EQ(status(access(p, {}, "token=" + token)), 200);  // page load, WebSocket upgrade
  EXPECT_EQ(status(access(p, {}, "token=nope")), 401);
  // A header, when present, is the one that counts.
  EXPECT_EQ(status(access(p, {{"Authorization", "Bearer nope"}}, "token=" + token)), 401);
}

// The page loaded with ?token= hands its browser a cookie, so that its script and style requests
// (which carry no token) pass; the cookie is per port, and a wrong one is refused like a header.
TEST(AccessPolicy, ThePagesCookieCarriesTheToken) {
  const std::string token = "0123456789abcdef0123456789abcdef";
  const AccessPolicy p = make_access_policy("192.0.2.10", 8080, token);
  EXPECT_EQ(token_cookie(p), "Set-Cookie: orthoflow_token_8080=" + token +
                                 "; Path=/; HttpOnly; SameSite=Strict\r\n");
  EXPECT_EQ(status(access(p, {{"Cookie", "orthoflow_token_8080=" + token}})), 200);
  EXPECT_EQ(status(access(p, {{"Cookie", "a=1; orthoflow_token_8080=" + token + "; b=2"}})), 200);
  EXPECT_EQ(status(access(p, {{"Cookie", "orthoflow_token_8081=" + token}})), 401);  // other port
  EXPECT_EQ(status(access(p, {{"Cookie", "orthoflow_token_8080=nope"}})), 401);
  EXPECT_EQ(status(access(p, {{"Cookie", "orthoflow_token_8080"}})), 401);
  EXPECT_EQ(status(access(p, {{"Cookie", ""}})), 401);
  // A header or a query, when present, is the one that counts.
  EXPECT_EQ(status(access(p, {{"Cookie", "orthoflow_token_8080=" + token}}, "token=nope")), 401);
  // No token, no cookie; a token a cookie cannot hold gets none (the page then needs a header).
  EXPECT_EQ(token_cookie(make_access_policy("127.0.0.1", 8080, "")), "");
  EXPECT_EQ(token_cookie(make_access_policy("192.0.2.10", 8080, "semi;colon-token-0123456")), "");
}
TEST(AccessPolicy, LoopbackNeedsNoTokenButItsOwnHost) {
  const AccessPolicy p = make_access_policy("127.0.0.1", 8080, "");
  EXPECT_EQ(status(access(p, {{"Host", "127.0.0.1:8080"}})), 200);
  EXPECT_EQ(status(access(p, {{"Host", "localhost:8080"}})), 200);
  // DNS rebinding: another name that resolves to 127.0.0.1, or no Host at all.
  EXPECT_EQ(status(access(p, {{"Host", "evil.example:8080"}})), 403);
  EXPECT_EQ(status(access(p, {{"Host", "127.0.0.1:9999"}})), 403);
  EXPECT_EQ(status(access(p, {})), 403);
}

TEST(AccessPolicy, AnotherOriginIsRefused) {
  const AccessPolicy p = make_access_policy("127.0.0.1", 8080, "");
  const HttpHeader host{"Host", "127.0.0.1:8080"};
  EXPECT_EQ(status(access(p, {host, {"Origin", "http://127.0.0.1:8080"}})), 200);
  EXPECT_EQ(status(access(p, {host, {"Origin", "http://localhost:8080"}})), 200);
  EXPECT_EQ(status(access(p, {host, {"Origin", "http://evil.example"}})), 403);
  EXPECT_EQ(status(access(p, {host, {"Origin", "null"}})), 403);
  EXPECT_EQ(status(access(p, {host, {"Origin", ""}})), 403);
  EXPECT_EQ(status(access(p, {host, {"Origin", "http://127.0.0.1:8081"}})), 403);
  const AccessPolicy lan = make_access_policy("192.0.2.10", 80, "t0123456789abcdef");
  const HttpHeader auth{"Authorization", "Bearer t0123456789abcdef"};
  EXPECT_EQ(status(access(lan, {auth, {"Origin", "http://192.0.2.10:80"}})), 200);
  EXPECT_EQ(status(access(lan, {auth, {"Origin", "http://192.0.2.11:80"}})), 403);
  // Any interface: its own origin is the name the browser used to reach it.
  const AccessPolicy any = make_access_policy("0.0.0.0", 80, "t0123456789abcdef");
  EXPECT_EQ(status(access(any, {auth, {"Host", "robot:80"}, {"Origin", "http://robot:80"}})), 200);
  EXPECT_EQ(status(access(any, {auth, {"Host", "robot:80"}, {"Origin", "http://evil:80"}})), 403);
}

TEST(AccessPolicy, ConstantTimeEqual) {
  EXPECT_TRUE(constant_time_equal("abc", "abc"));
  EXPECT_TRUE(constant_time_equal("", ""));
  EXPECT_FALSE(constant_time_equal("abc", "abd"));
  EXPECT_FALSE(constant_time_equal("abc", std::string_view("abc\0", 4)));
  EXPECT_FALSE(constant_time_equal("abc", "ab"));
  EXPECT_FALSE(constant_time_equal("", "a"));
}

TEST(RateLimiter, RefusesAFloodAndRefillsOverTime) {
  RateLimiter limiter({/*rate_per_s=*/10.0, /*burst=*/5.0, /*max_clients=*/2});
  int allowed = 0;
  for (int i = 0; i < 20; ++i) allowed += limiter.allow("10.0.0.1", 0) ? 1 : 0;
  EXPECT_EQ(allowed, 5);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(limiter.allow("10.0.0.2", 0));  // a bucket of its own
  EXPECT_FALSE(limiter.allow("10.0.0.1", 50'000'000));     // half a token after 50 ms
  EXPECT_TRUE(limiter.allow("10.0.0.1", 100'000'000));     // one token after 100 ms
  EXPECT_FALSE(limiter.allow("10.0.0.3", 100'000'000));    // table full of busy clients
  EXPECT_TRUE(limiter.allow("10.0.0.3", 10'000'000'000));  // idle buckets are dropped for it
  EXPECT_LE(limiter.clients(), 2U);
}

TEST(ServerConfig, ParsesListenAddresses) {
  UiServerConfig c;
  ASSERT_TRUE(parse_listen("8080", c));
  EXPECT_EQ(c.address, "127.0.0.1");
  EXPECT_EQ(c.port, 8080);
  ASSERT_TRUE(parse_listen("0.0.0.0:9000", c));
  EXPECT_EQ(c.address, "0.0.0.0");
  EXPECT_EQ(c.port, 9000);
  ASSERT_TRUE(parse_listen("localhost:81", c));
  EXPECT_EQ(c.address, "127.0.0.1");
  ASSERT_TRUE(parse_listen("0", c));  // a free port, chosen at bind time
  EXPECT_EQ(c.port, 0);
  for (const char* bad : {"", "-1", "65536", "80x", "host:80", "1.2.3:80", "1.2.3.4:", ":80"}) {
    UiServerConfig d;
    EXPECT_FALSE(parse_listen(bad, d)) << bad;
  }
}

TEST(ServerConfig, TokensAreRandomHexOrReadFromAFile) {
  const std::string a = generate_token(), b = generate_token();
  EXPECT_EQ(a.size(), 2 * TOKEN_BYTES);
  EXPECT_NE(a, b);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos);
  const auto dir =
      std::filesystem::temp_directory_path() / ("ui_token_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "good") << "  s3cret-token-0123456789 \nignored\n";
  std::ofstream(dir / "short") << "short\n";
  std::ofstream(dir / "space") << "has a space in the token\n";
  EXPECT_EQ(*read_token_file((dir / "good").string()), "s3cret-token-0123456789");
  EXPECT_FALSE(read_token_file((dir / "short").string()));
  EXPECT_FALSE(read_token_file((dir / "space").string()));
  EXPECT_FALSE(read_token_file((dir / "absent").string()));
  std::filesystem::remove_all(dir);
}

TEST(Assets, OnlyTheEmbeddedFilesByExactPath) {
  const Asset* index = find_asset("/");
  ASSERT_NE(index, nullptr);
  EXPECT_STREQ(index->content_type, "text/html; charset=utf-8");
  EXPECT_NE(index->text().find("<canvas id=\"top\""), std::string_view::npos);
  ASSERT_NE(find_asset("/app.js"), nullptr);
  EXPECT_NE(find_asset("/app.js")->text().find("/api/events"), std::string_view::npos);
  ASSERT_NE(find_asset("/style.css"), nullptr);
  ASSERT_NE(find_asset("/favicon.svg"),
            nullptr);  // a browser asks for an icon; 404s clutter its console
  EXPECT_STREQ(find_asset("/favicon.svg")->content_type, "image/svg+xml");
  for (const char* path : {"/../CMakeLists.txt", "/./app.js", "//app.js", "/app.js/", "/APP.JS",
                           "/assets/app.js", "", "/etc/passwd"}) {
    EXPECT_EQ(find_asset(path), nullptr) << path;
  }
  std::set<std::string_view> paths;
  for (const Asset& a : embedded_assets()) EXPECT_TRUE(paths.insert(a.path).second) << a.path;
}

}  // namespace
}  // namespace orthoflow::ui
