// UiServer over real loopback sockets with a recording backend: the checks every request passes
// (token, origin, host, body limit, rate limit), the WebSocket upgrade's checks and its stream, the
// status of each learning outcome, and assets (no path reaches the file system).
#include "ui/ui_server.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <mutex>

#include "http_test_client.hpp"
#include "ui/task_link.hpp"
#include "ui/ui_client.hpp"

namespace orthoflow::ui {
namespace {

using test::http;
using test::post_json;
using Outcome = graphs::LearningAck::Outcome;

/// Answers every action with a set outcome and remembers what it was sent.
class RecordingBackend : public UiBackend {
 public:
  UiSnapshot snapshot() const override {
    UiSnapshot s;
    s.frame_id = frames_.fetch_add(1) + 1;
    ObjectView o;
    o.track_id = 3;
    o.label = "mug";
    o.unknown = false;
    o.score = 0.125F;
    s.objects.push_back(o);
    s.memory.push_back({"mug", 4, 1700000000000});
    return s;
  }
  UiAnswer submit(const UiAction& action, int /*timeout_ms*/) override {
    std::lock_guard<std::mutex> guard(lock_);
    actions.push_back(action);
    UiAnswer a{status, {}};
    a.ack.outcome = outcome;
    a.ack.track_id = action.track;
    a.ack.label = action.label;
    return a;
  }
  std::string camera_png() override {
    std::lock_guard<std::mutex> guard(lock_);
    ++camera_requests;
    return png;
  }
  std::mutex lock_;
  std::vector<UiAction> actions;
  std::string png;  // what camera_png() answers ("" = no image)
  int camera_requests = 0;
  Outcome outcome = Outcome::LEARNED;
  UiAnswer::Status status = UiAnswer::Status::ACKNOWLEDGED;
  mutable std::atomic<std::uint64_t> frames_{0};
};

class UiServerTest : public ::testing::Test {
 protected:
  void start(std::string token = "", RateLimit rate = {1000.0, 1000.0, 64}) {
    UiServerConfig config;
    config.token = std::move(token);
    config.rate = rate;
    auto server_result = UiServer::start(config, backend_);
    ASSERT_TRUE(server_result) << server_result.error();
    server_ = std::move(*server_result);
    port_ = server_->port();
    ASSERT_NE(port_, 0);
  }
  RecordingBackend backend_;
  std::unique_ptr<UiServer> server_;
  std::uint16_t port_ = 0;
};

const std::string TOKEN = "test-token-0123456789abcdef";

TEST_F(UiServerTest, ServesStateAndAssetsOnLoopbackWithoutAToken) {
  start();
  EXPECT_EQ(server_->url(), "http://127.0.0.1:" + std::to_string(port_) + "/");
  const auto state = http(port_, "GET", "/api/state");
  ASSERT_EQ(state.status, 200) << state.head;
  const auto doc = nlohmann::json::parse(state.body);
  EXPECT_EQ(doc["objects"][0]["track"], 3);
  EXPECT_EQ(doc["objects"][0]["label"], "mug");
  EXPECT_EQ(doc["memory"][0]["views"], 4);
  const auto page = http(port_, "GET", "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.head.find("Content-Type: text/html"), std::string::npos);
  EXPECT_NE(page.head.find("Content-Security-Policy: default-src 'self'"), std::string::npos);
  EXPECT_NE(page.body.find("<canvas"), std::string::npos);
  EXPECT_NE(http(port_, "GET", "/app.js").head.find("text/javascript"), std::string::npos);
}

// GET /api/camera.png: the backend's PNG as image/png, a JSON 404 while there is none; GET only,
// and checked like any request (a token when the server has one).
TEST_F(UiServerTest, ServesTheCameraImageOrSaysThereIsNone) {
  start(TOKEN);
  const std::vector<std::pair<std::string, std::string>> auth = {
      {"Authorization", "Bearer " + TOKEN}};
  const auto none = http(port_, "GET", "/api/camera.png", auth);
  EXPECT_EQ(none.status, 404);
  EXPECT_NE(none.body.find("no camera image"), std::string::npos) << none.body;
  backend_.png = std::string("\x89PNG\r\n\x1a\n", 8) + "image bytes";
  const auto image = http(port_, "GET", "/api/camera.png?n=17", auth);
  ASSERT_EQ(image.status, 200);
  EXPECT_NE(image.head.find("Content-Type: image/png"), std::string::npos);
  EXPECT_NE(image.head.find("Cache-Control: no-store"), std::string::npos);
  EXPECT_EQ(image.body, backend_.png);
  EXPECT_EQ(http(port_, "GET", "/api/camera.png").status, 401);
  EXPECT_EQ(post_json(port_, "/api/camera.png", "{}", auth).status, 405);
  EXPECT_EQ(backend_.camera_requests, 2);  // the refused requests never reached the backend
}

TEST_F(UiServerTest, UnknownPathsAndTraversalAre404) {
  start();
  for (const char* path : {"/nothing", "/../CMakeLists.txt", "/%2e%2e/%2e%2e/etc/passwd",
                           "/..%2fui%2fCMakeLists.txt", "/assets/app.js", "/api/nope"}) {
    const auto r = http(port_, "GET", path);
    EXPECT_TRUE(r.status == 404 || r.status == 400) << path << ": " << r.head;
    EXPECT_EQ(r.body.find("add_library"), std::string::npos) << path;
  }
}

TEST_F(UiServerTest, TokenIsCheckedOnEveryRequest) {
  start(TOKEN);
  EXPECT_EQ(http(port_, "GET", "/api/state").status, 401);
  EXPECT_NE(http(port_, "GET", "/api/state").head.find("WWW-Authenticate: Bearer"),
            std::string::npos);
  EXPECT_EQ(http(port_, "GET", "/", {{"Authorization", "Bearer nope"}}).status, 401);
  EXPECT_EQ(post_json(port_, "/api/teach", R"({"track":3,"label":"cup"})").status, 401);
  EXPECT_TRUE(backend_.actions.empty());
  EXPECT_EQ(http(port_, "GET", "/api/state", {{"Authorization", "Bearer " + TOKEN}}).status, 200);
  EXPECT_EQ(http(port_, "GET", "/?token=" + TOKEN).status, 200);
  const auto taught = post_json(port_, "/api/teach", R"({"track":3,"label":"cup"})",
                                {{"Authorization", "Bearer " + TOKEN}});
  EXPECT_EQ(taught.status, 200) << taught.body;
  ASSERT_EQ(backend_.actions.size(), 1U);
  EXPECT_EQ(server_->url().find(TOKEN), std::string::npos) << "the printed URL never holds it";
}

// The page loaded with ?token= sets the token cookie, with which the browser fetches the page's
// script and style (their URLs carry no token); without the cookie they are refused.
TEST_F(UiServerTest, ThePageHandsItsBrowserTheTokenCookie) {
  start(TOKEN);
  const auto page = http(port_, "GET", "/?token=" + TOKEN);
  ASSERT_EQ(page.status, 200);
  const std::string cookie = "orthoflow_token_" + std::to_string(port_) + "=" + TOKEN;
  EXPECT_NE(page.head.find("Set-Cookie: " + cookie + "; Path=/; HttpOnly; SameSite=Strict"),
            std::string::npos)
      << page.head;
  EXPECT_EQ(http(port_, "GET", "/app.js").status, 401);
  EXPECT_EQ(http(port_, "GET", "/app.js", {{"Cookie", cookie}}).status, 200);
  EXPECT_EQ(http(port_, "GET", "/style.css", {{"Cookie", cookie}}).status, 200);
  EXPECT_EQ(http(port_, "GET", "/style.css", {{"Cookie", cookie + "x"}}).status, 401);
  // Only the page sets it; an API answer does not.
  EXPECT_EQ(http(port_, "GET", "/api/state", {{"Cookie", cookie}}).head.find("Set-Cookie"),
            std::string::npos);
}

TEST_F(UiServerTest, WebSocketUpgradeChecksTheTokenAndStreams) {
  start(TOKEN);
  std::string frame;
  EXPECT_EQ(test::websocket_first_frame(port_, "/api/events?hz=5", frame).status, 401);
  EXPECT_EQ(test::websocket_first_frame(port_, "/api/events?hz=5&token=bad", frame).status, 401);
  EXPECT_TRUE(frame.empty());
  const auto ok = test::websocket_first_frame(port_, "/api/events?hz=5&token=" + TOKEN, frame);
  ASSERT_EQ(ok.status, 101) << ok.head;
  const auto doc = nlohmann::json::parse(frame);
  EXPECT_EQ(doc["objects"][0]["label"], "mug");
  EXPECT_EQ(test::websocket_first_frame(port_, "/api/events?hz=0&token=" + TOKEN, frame).status,
            400);
  std::string other;
  EXPECT_EQ(test::websocket_first_frame(port_, "/api/events?token=" + TOKEN, other,
                                        {{"Origin", "http://evil.example"}})
                .status,
            403);
}

TEST_F(UiServerTest, CrossOriginAndForeignHostAreRefused) {
  start();
  const auto r =
      post_json(port_, "/api/forget", R"({"label":"mug"})", {{"Origin", "http://evil.example"}});
  EXPECT_EQ(r.status, 403);
  EXPECT_NE(r.body.find("cross-origin"), std::string::npos);
  EXPECT_TRUE(backend_.actions.empty());
  const std::string own = "http://127.0.0.1:" + std::to_string(port_);
  EXPECT_EQ(post_json(port_, "/api/forget", R"({"label":"mug"})", {{"Origin", own}}).status, 200);
  EXPECT_EQ(http(port_, "GET", "/api/state", {{"Host", "rebound.example"}}, "", false).status, 403);
}

TEST_F(UiServerTest, ACorsPreflightIsNeverGranted) {
  // civetweb answers a preflight itself with "Access-Control-Allow-Origin: *" unless told not to
  // (issue 52, item 4): with or without a token, from a foreign origin or our own.
  for (const bool with_token : {false, true}) {
    server_.reset();
    start(with_token ? TOKEN : "");
    const std::vector<std::string> origins{"http://evil.example",
                                           "http://127.0.0.1:" + std::to_string(port_)};
    for (const std::string& origin : origins) {
      std::vector<std::pair<std::string, std::string>> headers{
          {"Origin", origin},
          {"Access-Control-Request-Method", "POST"},
          {"Access-Control-Request-Headers", "content-type, authorization"}};
      if (with_token) headers.emplace_back("Authorization", "Bearer " + TOKEN);
      const auto r = http(port_, "OPTIONS", "/api/teach", headers);
      EXPECT_GE(r.status, 400) << origin << "\n" << r.head;
      EXPECT_EQ(r.head.find("Access-Control-Allow"), std::string::npos) << r.head;
    }
  }
  EXPECT_TRUE(backend_.actions.empty());
}

TEST_F(UiServerTest, BodyLimitAndMalformedInputGet4xxWithJson) {
  start();
  const auto big = post_json(port_, "/api/teach", std::string(MAX_BODY_BYTES + 10, ' '));
  EXPECT_EQ(big.status, 413);
  const auto bad = post_json(port_, "/api/teach", "{\"track\":");
  EXPECT_EQ(bad.status, 400);
  EXPECT_EQ(nlohmann::json::parse(bad.body)["error"], "the body is not valid JSON");
  const auto label = post_json(port_, "/api/teach", R"({"track":3,"label":"a\u0001"})");
  EXPECT_EQ(label.status, 400);
  EXPECT_EQ(nlohmann::json::parse(label.body)["error"], "label holds a control character");
  EXPECT_EQ(http(port_, "GET", "/api/teach").status, 405);
  EXPECT_EQ(http(port_, "GET", "/api/events").status, 426);
  EXPECT_TRUE(backend_.actions.empty());
}

TEST_F(UiServerTest, AFloodIsRateLimited) {
  start("", {/*rate_per_s=*/1.0, /*burst=*/5.0, /*max_clients=*/64});
  int ok = 0, limited = 0;
  for (int i = 0; i < 12; ++i) {
    const int s = http(port_, "GET", "/api/state").status;
    ok += s == 200 ? 1 : 0;
    limited += s == 429 ? 1 : 0;
  }
  EXPECT_GE(ok, 5);
  EXPECT_LE(ok, 7);  // the burst, and a token or so refilled while the loop ran
  EXPECT_EQ(ok + limited, 12);
}

TEST_F(UiServerTest, LearningOutcomesMapToStatuses) {
  start();
  const std::pair<Outcome, int> cases[] = {
      {Outcome::STORED, 200},         {Outcome::LEARNED, 200},      {Outcome::NO_SUCH_TRACK, 404},
      {Outcome::NOT_DESCRIBED, 409},  {Outcome::BAD_LABEL, 400},    {Outcome::REJECTED, 422},
      {Outcome::UNKNOWN_LABEL, 404},  {Outcome::WRITE_FAILED, 500}, {Outcome::BUSY, 503},
      {Outcome::NOTHING_TO_UNDO, 409}};
  for (const auto& [outcome, status] : cases) {
    backend_.outcome = outcome;
    const auto r = post_json(port_, "/api/correct", R"({"track":9,"label":"bowl"})");
    EXPECT_EQ(r.status, status) << graphs::to_string(outcome);
    EXPECT_EQ(nlohmann::json::parse(r.body)["outcome"], graphs::to_string(outcome));
  }
  backend_.outcome = Outcome::NOTHING_TO_UNDO;
  const auto undo = post_json(port_, "/api/undo", "{}");
  EXPECT_EQ(undo.status, 409);
  EXPECT_EQ(nlohmann::json::parse(undo.body)["action"], "undo");
  backend_.status = UiAnswer::Status::TIMEOUT;
  EXPECT_EQ(post_json(port_, "/api/ask", R"({"track":9})").status, 504);
  backend_.status = UiAnswer::Status::QUEUE_FULL;
  EXPECT_EQ(post_json(port_, "/api/ask", R"({"track":9})").status, 503);
  ASSERT_EQ(backend_.actions.size(), 13U);
  EXPECT_EQ(backend_.actions[0].kind, graphs::LearningCommand::Kind::CORRECT);
  EXPECT_EQ(backend_.actions[0].track, 9U);
  EXPECT_EQ(backend_.actions[0].label.view(), "bowl");
  EXPECT_EQ(backend_.actions[10].kind, graphs::LearningCommand::Kind::UNDO);
  EXPECT_EQ(backend_.actions[11].kind, graphs::LearningCommand::Kind::ASK);
}

// The program client (ui/ui_client.hpp) against the real server: the body goes out as JSON, the
// token when it has one, and a refusal comes back as a reply, not an error.
TEST_F(UiServerTest, ClientSendsActionsWithTheTokenAndReadsEveryAnswer) {
  start(TOKEN);
  auto target = parse_ui_url("http://127.0.0.1:" + std::to_string(port_) + "/");
  ASSERT_TRUE(target) << target.error();
  auto denied = send_ui_request(*target, "GET", "/api/state", "");
  ASSERT_TRUE(denied) << denied.error();
  EXPECT_EQ(denied->status, 401);
  target->token = TOKEN;
  auto state = send_ui_request(*target, "GET", "/api/state", "");
  ASSERT_TRUE(state) << state.error();
  EXPECT_EQ(state->status, 200);
  EXPECT_EQ(nlohmann::json::parse(state->body)["objects"][0]["label"], "mug");
  auto taught = send_ui_request(*target, "POST", "/api/teach", R"({"track":5,"label":"bowl"})");
  ASSERT_TRUE(taught) << taught.error();
  EXPECT_EQ(taught->status, 200);
  ASSERT_EQ(backend_.actions.size(), 1U);
  EXPECT_EQ(backend_.actions[0].track, 5U);
  EXPECT_EQ(backend_.actions[0].label.view(), "bowl");
  backend_.outcome = Outcome::NOTHING_TO_UNDO;
  auto undo = send_ui_request(*target, "POST", "/api/undo", "{}");
  ASSERT_TRUE(undo) << undo.error();
  EXPECT_EQ(undo->status, 409);
  EXPECT_EQ(nlohmann::json::parse(undo->body)["outcome"], "nothing_to_undo");
  auto bad = send_ui_request(*target, "POST", "/api/teach", "{not json");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
}

TEST(UiClient, UrlsAreCheckedAndAnUnreachableServerIsAnError) {
  auto ok = parse_ui_url("http://robot.local:8080");
  ASSERT_TRUE(ok) << ok.error();
  EXPECT_EQ(ok->host, "robot.local");
  EXPECT_EQ(ok->port, 8080);
  for (const char* bad :
       {"https://127.0.0.1:80", "127.0.0.1:80", "http://127.0.0.1", "http://127.0.0.1:0",
        "http://127.0.0.1:65536", "http://127.0.0.1:80/api", "http://u:p@127.0.0.1:80",
        "http://:80", "http://127.0.0.1:8x", "http://127.0.0.1:80?token=x"}) {
    EXPECT_FALSE(parse_ui_url(bad)) << bad;
  }
  // A port nothing listens on (bound, never listening): refused at once.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  ClientTarget target;
  target.host = "127.0.0.1";
  target.port = ntohs(addr.sin_port);
  auto r = send_ui_request(target, "GET", "/api/state", "");
  ::close(fd);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("cannot connect"), std::string::npos) << r.error();
}

/// A task process stand-in behind the TaskLink interface: answers every command as set and
/// remembers what it was sent (the real link, over iceoryx, is tested in tests/ipc/ipc_task_test).
class RecordingTaskLink : public TaskLink {
 public:
  std::optional<TaskView> view() const override {
    std::lock_guard<std::mutex> guard(lock_);
    return shown;
  }
  TaskReply send(const graphs::TaskCommand& command, int /*timeout_ms*/) override {
    std::lock_guard<std::mutex> guard(lock_);
    sent.push_back(command);
    return reply;
  }
  ArmStopReply stop_arm(int /*timeout_ms*/) override {
    std::lock_guard<std::mutex> guard(lock_);
    ++stops;
    return stop_reply;
  }
  mutable std::mutex lock_;
  std::optional<TaskView> shown;
  TaskReply reply;
  std::vector<graphs::TaskCommand> sent;
  ArmStopReply stop_reply;
  int stops = 0;
};

// POST /api/arm/stop (the stop button): 503 without a link or a holder, 504 when the holder does
// not confirm, 200 with what the holder said; extra fields refused before anything is sent.
TEST_F(UiServerTest, ArmStopReachesTheHolderAndSaysWhatItStopped) {
  start();
  EXPECT_EQ(post_json(port_, "/api/arm/stop", "{}").status, 503);
  RecordingTaskLink link;
  backend_.set_task_link(&link);
  link.stop_reply.status = ArmStopReply::Status::NO_HOLDER;
  EXPECT_EQ(post_json(port_, "/api/arm/stop", "{}").status, 503);
  link.stop_reply.status = ArmStopReply::Status::TIMEOUT;
  EXPECT_EQ(post_json(port_, "/api/arm/stop", "{}").status, 504);
  link.stop_reply = {ArmStopReply::Status::STOPPED, true, 4242, "orthoflow task run", 3.5};
  const auto stopped = post_json(port_, "/api/arm/stop", "{}");
  ASSERT_EQ(stopped.status, 200) << stopped.body;
  const auto doc = nlohmann::json::parse(stopped.body);
  EXPECT_EQ(doc["was_moving"], true);
  EXPECT_EQ(doc["holder_pid"], 4242);
  EXPECT_EQ(doc["latched"], true);
  EXPECT_EQ(post_json(port_, "/api/arm/stop", R"({"now": 1})").status, 400);
  EXPECT_EQ(link.stops, 3);
  backend_.set_task_link(nullptr);
}

// POST /api/task/start and /api/task/stop: without a task link 503; with one, the task process's
// answer (started / stopping 200, refused 409, invalid 400), no task process 503, no answer 504;
// the state shows whether tasks can be sent and the task's newest state.
TEST_F(UiServerTest, TaskCommandsReachTheTaskProcessAndItsAnswerComesBack) {
  start();
  const std::string clear = R"({"task": "clear_table"})";
  auto none = post_json(port_, "/api/task/start", clear);
  EXPECT_EQ(none.status, 503);
  EXPECT_NE(none.body.find("no task control here"), std::string::npos) << none.body;
  auto doc = nlohmann::json::parse(http(port_, "GET", "/api/state").body);
  EXPECT_EQ(doc["tasks"], false);
  EXPECT_TRUE(doc["task"].is_null());

  RecordingTaskLink link;
  backend_.set_task_link(&link);
  graphs::TaskStatus status;
  status.state = graphs::TaskState::RUNNING;
  status.answer = graphs::TaskAnswer::STARTED;
  status.moves = 3;
  status.move = 1;
  status.phase = manipulation::Phase::APPROACH;
  link.reply = {TaskReply::Status::ANSWERED, status};
  link.shown = TaskView{status, 42};
  const auto started = post_json(port_, "/api/task/start", clear);
  ASSERT_EQ(started.status, 200) << started.body;
  const auto answer = nlohmann::json::parse(started.body);
  EXPECT_EQ(answer["ok"], true);
  EXPECT_EQ(answer["answer"], "started");
  EXPECT_EQ(answer["task"], "clear_table");
  EXPECT_EQ(answer["moves"], 3);
  doc = nlohmann::json::parse(http(port_, "GET", "/api/state").body);
  EXPECT_EQ(doc["tasks"], true);
  EXPECT_EQ(doc["task"]["state"], "running");
  EXPECT_EQ(doc["task"]["phase"], "approach");
  EXPECT_EQ(doc["task"]["age_ms"], 42);

  status.answer = graphs::TaskAnswer::REFUSED;
  status.message = "a task is running";
  link.reply = {TaskReply::Status::ANSWERED, status};
  const auto refused =
      post_json(port_, "/api/task/start", R"({"task": "serve_a_meal", "bring": ["mug"]})");
  EXPECT_EQ(refused.status, 409);
  EXPECT_EQ(nlohmann::json::parse(refused.body)["message"], "a task is running");
  status.answer = graphs::TaskAnswer::STOPPING;
  link.reply = {TaskReply::Status::ANSWERED, status};
  EXPECT_EQ(post_json(port_, "/api/task/stop", "{}").status, 200);
  link.reply = {TaskReply::Status::NO_TASK_PROCESS, {}};
  EXPECT_EQ(post_json(port_, "/api/task/stop", "{}").status, 503);
  link.reply = {TaskReply::Status::TIMEOUT, {}};
  EXPECT_EQ(post_json(port_, "/api/task/stop", "{}").status, 504);
  EXPECT_EQ(post_json(port_, "/api/task/start", R"({"task": "fly"})").status, 400);  // not sent
  ASSERT_EQ(link.sent.size(), 5U);
  EXPECT_EQ(link.sent[1].bring, std::vector<std::string>{"mug"});
  EXPECT_EQ(link.sent[2].kind, graphs::TaskCommand::Kind::STOP);
  backend_.set_task_link(nullptr);
}

}  // namespace
}  // namespace orthoflow::ui
