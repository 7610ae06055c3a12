// decode_request (ui/api_request.hpp): every route and every error path, with the status and a
// message; label validation through the one label rule.
#include "ui/api_request.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace orthoflow::ui {
namespace {

using Kind = ApiRequest::Kind;

const std::vector<HttpHeader> JSON_TYPE = {{"content-type", "application/json; charset=utf-8"}};

Result<ApiRequest, ApiError> decode(std::string_view method, std::string_view path,
                                    std::string_view body = "", std::string_view query = "",
                                    const std::vector<HttpHeader>& headers = JSON_TYPE) {
  return decode_request(RawRequest{method, path, query, headers, body});
}

int status_of(const Result<ApiRequest, ApiError>& r) { return r ? 200 : r.error().status; }

TEST(ApiRequest, DecodesEveryRoute) {
  EXPECT_EQ(decode("GET", "/api/state")->kind, Kind::STATE);
  auto events = decode("GET", "/api/events", "", "hz=5");
  ASSERT_TRUE(events);
  EXPECT_EQ(events->kind, Kind::EVENTS);
  EXPECT_DOUBLE_EQ(events->hz, 5.0);
  EXPECT_DOUBLE_EQ(decode("GET", "/api/events")->hz, DEFAULT_STREAM_HZ);
  auto teach = decode("POST", "/api/teach", R"({"track": 7, "label": "mug"})");
  ASSERT_TRUE(teach);
  EXPECT_EQ(teach->kind, Kind::TEACH);
  EXPECT_EQ(teach->track, 7U);
  EXPECT_EQ(teach->label.view(), "mug");
  EXPECT_EQ(decode("POST", "/api/correct", R"({"track":1,"label":"bowl"})")->kind, Kind::CORRECT);
  auto ask = decode("POST", "/api/ask", R"({"track": 4294967295})");
  ASSERT_TRUE(ask);
  EXPECT_EQ(ask->track, 4294967295U);
  auto forget = decode("POST", "/api/forget", R"({"label": "tasse à café"})");
  ASSERT_TRUE(forget);
  EXPECT_EQ(forget->label.view(), "tasse à café");
  EXPECT_EQ(decode("POST", "/api/undo", "{}")->kind, Kind::UNDO);
  auto asset = decode("GET", "/app.js");
  ASSERT_TRUE(asset);
  EXPECT_EQ(asset->kind, Kind::ASSET);
  EXPECT_EQ(asset->asset, "/app.js");
}

TEST(ApiRequest, WrongMethodIs405AndNoActionIsAGet) {
  for (const char* path : {"/api/teach", "/api/correct", "/api/ask", "/api/forget", "/api/undo"}) {
    const auto r = decode("GET", path, R"({"track":1,"label":"x"})");
    EXPECT_EQ(status_of(r), 405) << path;
    EXPECT_NE(r.error().message.find("POST"), std::string::npos);
  }
  EXPECT_EQ(status_of(decode("POST", "/api/state")), 405);
  EXPECT_EQ(status_of(decode("DELETE", "/api/forget", R"({"label":"x"})")), 405);
  EXPECT_EQ(status_of(decode("POST", "/index.html")), 405);
  EXPECT_EQ(status_of(decode("PUT", "/")), 405);
}

TEST(ApiRequest, UnknownApiPathIs404) {
  EXPECT_EQ(status_of(decode("GET", "/api/nothing")), 404);
  EXPECT_EQ(status_of(decode("POST", "/api/teach/", R"({"track":1,"label":"x"})")), 404);
  EXPECT_EQ(status_of(decode("GET", "/api")), 404);
}

TEST(ApiRequest, BodyLimitIs413) {
  const std::string big(MAX_BODY_BYTES + 1, ' ');
  EXPECT_EQ(status_of(decode("POST", "/api/teach", big)), 413);
  std::string fits = R"({"track":1,"label":"x"})";
  fits.resize(MAX_BODY_BYTES, ' ');  // trailing white space is valid JSON
  EXPECT_TRUE(decode("POST", "/api/teach", fits));
}

TEST(ApiRequest, ActionsNeedAJsonContentType) {
  const std::string body = R"({"track":1,"label":"x"})";
  EXPECT_EQ(status_of(decode("POST", "/api/teach", body, "", {})), 415);
  EXPECT_EQ(status_of(decode("POST", "/api/teach", body, "", {{"Content-Type", "text/plain"}})),
            415);
  EXPECT_EQ(status_of(decode("POST", "/api/teach", body, "",
                             {{"Content-Type", "application/x-www-form-urlencoded"}})),
            415);
  EXPECT_TRUE(decode("POST", "/api/teach", body, "", {{"CONTENT-TYPE", "Application/JSON"}}));
}

TEST(ApiRequest, MalformedJsonIs400WithAMessage) {
  for (const char* body : {"", "{", "{\"track\":1,", "nul", "\xff\xfe", "{\"track\":1}}"}) {
    const auto r = decode("POST", "/api/ask", body);
    EXPECT_EQ(status_of(r), 400) << body;
    EXPECT_FALSE(r.error().message.empty());
  }
  EXPECT_EQ(decode("POST", "/api/ask", "[1]").error().message, "the body must be a JSON object");
}

TEST(ApiRequest, FieldsAreCheckedOneByOne) {
  auto message = [](const char* path, const char* body) {
    const auto r = decode("POST", path, body);
    return r ? std::string("accepted") : r.error().message;
  };
  EXPECT_EQ(message("/api/ask", "{}"), "missing field 'track'");
  EXPECT_EQ(message("/api/teach", R"({"track":1})"), "missing field 'label'");
  EXPECT_EQ(message("/api/ask", R"({"track":"1"})"), "'track' must be an integer track id");
  EXPECT_EQ(message("/api/ask", R"({"track":1.5})"), "'track' must be an integer track id");
  EXPECT_EQ(message("/api/ask", R"({"track":0})"),
            "'track' must be a track id from 1 to 4294967295");
  EXPECT_EQ(message("/api/ask", R"({"track":-3})"),
            "'track' must be a track id from 1 to 4294967295");
  EXPECT_EQ(message("/api/ask", R"({"track":4294967296})"),
            "'track' must be a track id from 1 to 4294967295");
  EXPECT_EQ(message("/api/teach", R"({"track":1,"label":3})"), "'label' must be a string");
  EXPECT_EQ(message("/api/ask", R"({"track":1,"label":"x"})"), "unknown field 'label'");
  EXPECT_EQ(message("/api/forget", R"({"label":"x","track":1})"), "unknown field 'track'");
  EXPECT_EQ(message("/api/undo", R"({"label":"x"})"), "unknown field 'label'");
  EXPECT_EQ(message("/api/undo", "[]"), "the body must be a JSON object");
  EXPECT_EQ(message("/api/teach", R"({"track":1,"label":"x","lable":"y"})"),
            "unknown field 'lable'");
  // A key twice is refused, never "the last one wins" (issue 52, item 11).
  EXPECT_EQ(message("/api/teach", R"({"track":1,"label":"mug","label":"bowl"})"),
            "the key 'label' appears twice in one object");
  EXPECT_EQ(message("/api/ask", R"({"track":1,"track":2})"),
            "the key 'track' appears twice in one object");
}

TEST(ApiRequest, LabelsFollowTheLabelRule) {
  auto teach = [](const std::string& label_json) {
    return decode("POST", "/api/teach", R"({"track":1,"label":)" + label_json + "}");
  };
  EXPECT_EQ(teach(R"("")").error().message, "label is empty");
  EXPECT_EQ(teach("\"" + std::string(64, 'a') + "\"").error().message,
            "label is longer than 63 bytes");
  EXPECT_TRUE(teach("\"" + std::string(63, 'a') + "\""));
  EXPECT_EQ(teach(R"("a\nb")").error().message, "label holds a control character");
  EXPECT_EQ(teach(R"("tab\there")").error().message, "label holds a control character");
  EXPECT_EQ(teach(R"("nul\u0000")").error().message, "label holds a control character");
  EXPECT_EQ(teach(R"("c1\u0085")").error().message, "label holds a control character");
  // A lone surrogate escape decodes to bytes that are not UTF-8; raw invalid bytes are not JSON.
  EXPECT_EQ(status_of(teach("\"\xc3\x28\"")), 400);
  EXPECT_EQ(status_of(teach(R"("\ud800")")), 400);
  // 21 three-byte characters = 63 bytes fit; 22 do not.
  std::string cups;
  for (int i = 0; i < 21; ++i) cups += "\xe2\x98\x95";
  EXPECT_TRUE(teach("\"" + cups + "\""));
  EXPECT_EQ(teach("\"" + cups + "\xe2\x98\x95\"").error().message, "label is longer than 63 bytes");
  for (const char* path : {"/api/correct", "/api/forget"}) {
    const std::string body = std::string(path) == "/api/forget"
                                 ? R"({"label":"a\u0007"})"
                                 : R"({"track":2,"label":"a\u0007"})";
    EXPECT_EQ(decode("POST", path, body).error().message, "label holds a control character");
  }
  // Look-alike labels (issue 52, item 7): invisible and direction-control characters are refused; a
  // decomposed accent is composed (NFC), so "café" typed either way is one category.
  for (const char* hidden :
       {R"("mug\u200b")", R"("m\u202eug")", R"("mug\ufe0f")", R"("\u2066mug")", R"("mu\u00adg")"})
    EXPECT_EQ(teach(hidden).error().message,
              "label holds an invisible or direction-control character")
        << hidden;
  auto composed = teach(R"("cafe\u0301")");
  ASSERT_TRUE(composed);
  EXPECT_EQ(composed->label.view(), "caf\u00e9");
}

TEST(ApiRequest, StreamRateMustBeAPositiveNumber) {
  for (const char* q : {"hz=", "hz=0", "hz=-1", "hz=abc", "hz=5x", "hz=nan", "hz=inf"}) {
    EXPECT_EQ(status_of(decode("GET", "/api/events", "", q)), 400) << q;
  }
  EXPECT_DOUBLE_EQ(decode("GET", "/api/events", "", "token=t&hz=2.5")->hz, 2.5);
  EXPECT_DOUBLE_EQ(decode("GET", "/api/events", "", "hz=1000")->hz, 1000.0);  // clamped later
}

TEST(ApiRequest, StreamCameraFlagIsZeroOrOne) {
  EXPECT_FALSE(decode("GET", "/api/events")->camera);
  EXPECT_TRUE(decode("GET", "/api/events", "", "hz=5&camera=1")->camera);
  EXPECT_DOUBLE_EQ(decode("GET", "/api/events", "", "camera=1&hz=5")->hz, 5.0);
  EXPECT_FALSE(decode("GET", "/api/events", "", "camera=0")->camera);
  for (const char* q : {"camera=", "camera=2", "camera=yes", "camera=1&hz=0"})
    EXPECT_EQ(status_of(decode("GET", "/api/events", "", q)), 400) << q;
}

TEST(ApiRequest, QueryAndHeaderHelpers) {
  bool present = false;
  EXPECT_EQ(query_value("a=1&token=xyz&b", "token", &present), "xyz");
  EXPECT_TRUE(present);
  EXPECT_EQ(query_value("b", "b", &present), "");
  EXPECT_TRUE(present);
  EXPECT_EQ(query_value("tokens=1", "token", &present), "");
  EXPECT_FALSE(present);
  const std::vector<HttpHeader> h = {{"ORIGIN", "http://x"}};
  EXPECT_EQ(find_header(h, "origin", &present), "http://x");
  EXPECT_TRUE(present);
  EXPECT_EQ(find_header(h, "host", &present), "");
  EXPECT_FALSE(present);
}

}  // namespace
}  // namespace orthoflow::ui

namespace orthoflow::ui {
namespace {

TEST(ApiRequest, TaskStartAndStop) {
  auto clear = decode("POST", "/api/task/start", R"({"task": "clear_table"})");
  ASSERT_TRUE(clear);
  EXPECT_EQ(clear->kind, Kind::TASK_START);
  EXPECT_EQ(clear->task.kind, graphs::TaskCommand::Kind::START);
  EXPECT_EQ(clear->task.task, manipulation::TableTaskKind::CLEAR_TABLE);
  EXPECT_TRUE(clear->task.bring.empty());
  auto serve = decode("POST", "/api/task/start",
                      R"({"task": "serve_a_meal", "bring": ["mug", "bol à café"]})");
  ASSERT_TRUE(serve);
  EXPECT_EQ(serve->task.task, manipulation::TableTaskKind::SERVE_A_MEAL);
  EXPECT_EQ(serve->task.bring, (std::vector<std::string>{"mug", "bol à café"}));
  auto stop = decode("POST", "/api/task/stop", "{}");
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->kind, Kind::TASK_STOP);
  EXPECT_EQ(stop->task.kind, graphs::TaskCommand::Kind::STOP);
  EXPECT_EQ(to_string(Kind::TASK_START), "task_start");
}

TEST(ApiRequest, BadTaskCommandsAre400WithTheReason) {
  const auto reason = [](std::string_view path, std::string_view body) {
    const auto r = decode("POST", path, body);
    EXPECT_FALSE(r) << body;
    return r ? std::string() : std::to_string(r.error().status) + " " + r.error().message;
  };
  EXPECT_EQ(reason("/api/task/start", "{}"), "400 missing field 'task'");
  EXPECT_EQ(reason("/api/task/start", R"({"task": "dance"})"),
            "400 'task' must be \"clear_table\" or \"serve_a_meal\"");
  EXPECT_EQ(reason("/api/task/start", R"({"task": 3})"),
            "400 'task' must be \"clear_table\" or \"serve_a_meal\"");
  EXPECT_EQ(reason("/api/task/start", R"({"task": "clear_table", "bring": ["mug"]})"),
            "400 'bring' is for serve_a_meal only");
  EXPECT_EQ(reason("/api/task/start", R"({"task": "serve_a_meal"})"),
            "400 'bring' must list 1 to 4 categories");
  EXPECT_EQ(reason("/api/task/start", R"({"task": "serve_a_meal", "bring": []})"),
            "400 'bring' must list 1 to 4 categories");
  EXPECT_EQ(
      reason("/api/task/start", R"({"task": "serve_a_meal", "bring": ["a","b","c","d","e"]})"),
      "400 'bring' must list 1 to 4 categories");
  EXPECT_EQ(reason("/api/task/start", R"({"task": "serve_a_meal", "bring": [1]})"),
            "400 'bring' must list category names");
  EXPECT_NE(reason("/api/task/start", R"({"task": "serve_a_meal", "bring": ["a\u0001"]})")
                .find("400 'bring': "),
            std::string::npos);
  EXPECT_EQ(reason("/api/task/start", R"({"task": "clear_table", "speed": 2})"),
            "400 unknown field 'speed'");
  EXPECT_EQ(reason("/api/task/stop", R"({"now": true})"), "400 unknown field 'now'");
  EXPECT_EQ(status_of(decode("GET", "/api/task/start")), 405);
  EXPECT_EQ(status_of(decode("POST", "/api/task/stop", "{}", "", {})), 415);
  EXPECT_EQ(status_of(decode("POST", "/api/task")), 404);
  auto arm_stop = decode("POST", "/api/arm/stop", "{}");
  ASSERT_TRUE(arm_stop);
  EXPECT_EQ(arm_stop->kind, Kind::ARM_STOP);
  EXPECT_EQ(reason("/api/arm/stop", R"({"reason": "x"})"), "400 unknown field 'reason'");
  EXPECT_EQ(status_of(decode("GET", "/api/arm/stop")), 405);
}

}  // namespace
}  // namespace orthoflow::ui
