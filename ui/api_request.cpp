#include "ui/api_request.hpp"

#include <nlohmann/json.hpp>

#include <charconv>
#include <cmath>
#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/label_text.hpp"

namespace orthoflow::ui {

namespace {

using Kind = ApiRequest::Kind;
using Json = nlohmann::json;

Unexpected<ApiError> refuse(int status, std::string message) {
  return err(ApiError{status, std::move(message)});
}

bool equal_ignoring_case(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c + 32) : c; };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

struct Route {
  std::string_view path;
  Kind kind;
  bool post;
};
constexpr Route ROUTES[] = {
    {"/api/state", Kind::STATE, false},
    {"/api/events", Kind::EVENTS, false},
    {"/api/teach", Kind::TEACH, true},
    {"/api/correct", Kind::CORRECT, true},
    {"/api/ask", Kind::ASK, true},
    {"/api/forget", Kind::FORGET, true},
    {"/api/undo", Kind::UNDO, true},
    {"/api/camera.png", Kind::CAMERA, false},
    {"/api/task/start", Kind::TASK_START, true},
    {"/api/task/stop", Kind::TASK_STOP, true},
    {"/api/arm/stop", Kind::ARM_STOP, true},
};

// "application/json", optionally followed by parameters ("; charset=utf-8"). Requiring it also
// keeps cross-site forms out: a browser sends this type from another origin only after a preflight.
bool is_json_type(std::string_view type) noexcept {
  const std::size_t end = type.find(';');
  std::string_view media = type.substr(0, end);
  while (!media.empty() && (media.back() == ' ' || media.back() == '\t')) media.remove_suffix(1);
  return equal_ignoring_case(media, "application/json");
}

Result<std::uint32_t, ApiError> track_of(const Json& body) {
  const auto it = body.find("track");
  if (it == body.end()) return refuse(400, "missing field 'track'");
  if (!it->is_number_integer()) return refuse(400, "'track' must be an integer track id");
  if (it->is_number_unsigned()) {
    const auto id = it->get<std::uint64_t>();
    if (id >= 1 && id <= 0xFFFFFFFFU) return static_cast<std::uint32_t>(id);
  }
  return refuse(400, "'track' must be a track id from 1 to 4294967295");
}

Result<core::Text, ApiError> label_of(const Json& body) {
  const auto it = body.find("label");
  if (it == body.end()) return refuse(400, "missing field 'label'");
  if (!it->is_string()) return refuse(400, "'label' must be a string");
  // What a person typed, composed (NFC); invisible and direction-control characters are refused.
  const auto text = core::normalized_label(it->get_ref<const std::string&>());
  if (!text) return refuse(400, std::string(core::to_string(text.error())));
  core::Text label;
  if (!label.try_assign(*text)) return refuse(400, "label does not fit");  // checked above
  return label;
}

// Every key of the body must be one the action reads: a misspelt field is an error, not ignored.
std::optional<ApiError> only_fields(const Json& body,
                                    std::initializer_list<std::string_view> keys) {
  for (const auto& [key, value] : body.items()) {
    bool known = false;
    for (const std::string_view k : keys) known = known || key == k;
    if (!known) return ApiError{400, "unknown field '" + key.substr(0, 64) + "'"};
  }
  return std::nullopt;
}

// POST /api/task/start {"task": "clear_table"} or {"task": "serve_a_meal", "bring": [labels]};
// POST /api/task/stop {}.
Result<ApiRequest, ApiError> decode_task(Kind kind, const Json& body) {
  ApiRequest decoded;
  decoded.kind = kind;
  if (kind == Kind::TASK_STOP) {
    if (auto extra = only_fields(body, {})) return err(std::move(*extra));
    decoded.task.kind = graphs::TaskCommand::Kind::STOP;
    return decoded;
  }
  if (auto extra = only_fields(body, {"task", "bring"})) return err(std::move(*extra));
  const auto task = body.find("task");
  if (task == body.end()) return refuse(400, "missing field 'task'");
  if (!task->is_string() || (*task != "clear_table" && *task != "serve_a_meal"))
    return refuse(400, "'task' must be \"clear_table\" or \"serve_a_meal\"");
  decoded.task.kind = graphs::TaskCommand::Kind::START;
  const bool serve = *task == "serve_a_meal";
  decoded.task.task =
      serve ? manipulation::TableTaskKind::SERVE_A_MEAL : manipulation::TableTaskKind::CLEAR_TABLE;
  const auto bring = body.find("bring");
  if (!serve) {
    if (bring != body.end()) return refuse(400, "'bring' is for serve_a_meal only");
    return decoded;
  }
  if (bring == body.end() || !bring->is_array() || bring->empty() ||
      bring->size() > graphs::TASK_MAX_BRING)
    return refuse(
        400, "'bring' must list 1 to " + std::to_string(graphs::TASK_MAX_BRING) + " categories");
  for (const Json& label : *bring) {
    if (!label.is_string()) return refuse(400, "'bring' must list category names");
    const auto text = core::normalized_label(label.get_ref<const std::string&>());
    if (!text) return refuse(400, "'bring': " + std::string(core::to_string(text.error())));
    decoded.task.bring.push_back(*text);
  }
  return decoded;
}

Result<ApiRequest, ApiError> decode_action(Kind kind, const RawRequest& request) {
  if (!is_json_type(find_header(request.headers, "Content-Type")))
    return refuse(415, "an action needs Content-Type: application/json");
  // A key twice in one object is refused (nlohmann keeps the last one without a word): a body that
  // says two things is not acted on (issue 52, item 11).
  std::vector<std::set<std::string>> keys;  // one set per open object
  std::optional<std::string> repeated;
  const auto once = [&](int, Json::parse_event_t event, Json& parsed) {
    if (event == Json::parse_event_t::object_start) keys.emplace_back();
    if (event == Json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    if (event == Json::parse_event_t::key && !keys.empty() && !repeated &&
        !keys.back().insert(parsed.get<std::string>()).second)
      repeated = parsed.get<std::string>();
    return true;
  };
  const Json body = Json::parse(request.body, once, /*allow_exceptions=*/false);
  if (body.is_discarded()) return refuse(400, "the body is not valid JSON");
  if (repeated) return refuse(400, "the key '" + *repeated + "' appears twice in one object");
  if (!body.is_object()) return refuse(400, "the body must be a JSON object");
  if (kind == Kind::TASK_START || kind == Kind::TASK_STOP) return decode_task(kind, body);
  if (kind == Kind::ARM_STOP) {  // POST /api/arm/stop {}
    if (auto extra = only_fields(body, {})) return err(std::move(*extra));
    ApiRequest decoded;
    decoded.kind = kind;
    return decoded;
  }
  ApiRequest decoded;
  decoded.kind = kind;
  const bool needs_track = kind != Kind::FORGET && kind != Kind::UNDO,
             needs_label = kind != Kind::ASK && kind != Kind::UNDO;
  if (auto extra = needs_track && needs_label ? only_fields(body, {"track", "label"})
                   : needs_track              ? only_fields(body, {"track"})
                   : needs_label              ? only_fields(body, {"label"})
                                              : only_fields(body, {})) {
    return err(std::move(*extra));
  }
  if (needs_track) {
    auto track_result = track_of(body);
    if (!track_result) return err(track_result.error());
    decoded.track = *track_result;
  }
  if (needs_label) {
    auto label_result = label_of(body);
    if (!label_result) return err(label_result.error());
    decoded.label = *label_result;
  }
  return decoded;
}

Result<ApiRequest, ApiError> decode_events(const RawRequest& request) {
  ApiRequest decoded;
  decoded.kind = Kind::EVENTS;
  bool present = false;
  const std::string_view camera = query_value(request.query, "camera", &present);
  if (present && camera != "0" && camera != "1") return refuse(400, "'camera' must be 0 or 1");
  decoded.camera = camera == "1";
  const std::string_view text = query_value(request.query, "hz", &present);
  if (!present) return decoded;
  double hz = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), hz);
  if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(hz) || hz <= 0.0)
    return refuse(400, "'hz' must be a positive number");
  decoded.hz = hz;
  return decoded;
}

}  // namespace

std::string_view to_string(ApiRequest::Kind kind) noexcept {
  switch (kind) {
    case Kind::STATE:
      return "state";
    case Kind::EVENTS:
      return "events";
    case Kind::TEACH:
      return "teach";
    case Kind::CORRECT:
      return "correct";
    case Kind::ASK:
      return "ask";
    case Kind::FORGET:
      return "forget";
    case Kind::UNDO:
      return "undo";
    case Kind::CAMERA:
      return "camera";
    case Kind::TASK_START:
      return "task_start";
    case Kind::TASK_STOP:
      return "task_stop";
    case Kind::ARM_STOP:
      return "arm_stop";
    case Kind::ASSET:
      return "asset";
  }
  return "?";
}

std::string_view find_header(std::span<const HttpHeader> headers, std::string_view name,
                             bool* present) noexcept {
  for (const HttpHeader& h : headers) {
    if (equal_ignoring_case(h.name, name)) {
      if (present != nullptr) *present = true;
      return h.value;
    }
  }
  if (present != nullptr) *present = false;
  return {};
}

std::string_view query_value(std::string_view query, std::string_view key, bool* present) noexcept {
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    const std::size_t eq = pair.find('=');
    if (pair.substr(0, eq) == key) {
      if (present != nullptr) *present = true;
      return eq == std::string_view::npos ? std::string_view{} : pair.substr(eq + 1);
    }
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
  }
  if (present != nullptr) *present = false;
  return {};
}

Result<ApiRequest, ApiError> decode_request(const RawRequest& request) {
  if (request.body.size() > MAX_BODY_BYTES)
    return refuse(413, "the body is larger than " + std::to_string(MAX_BODY_BYTES) + " bytes");
  const bool get = request.method == "GET", post = request.method == "POST";
  for (const Route& route : ROUTES) {
    if (request.path != route.path) continue;
    if (route.post && !post) return refuse(405, "use POST for " + std::string(route.path));
    if (!route.post && !get) return refuse(405, "use GET for " + std::string(route.path));
    if (route.kind == Kind::STATE) return ApiRequest{};
    if (route.kind == Kind::CAMERA) {
      ApiRequest camera;
      camera.kind = Kind::CAMERA;
      return camera;
    }
    if (route.kind == Kind::EVENTS) return decode_events(request);
    return decode_action(route.kind, request);
  }
  if (request.path.substr(0, 5) == "/api/" || request.path == "/api")
    return refuse(404, "no such API path");
  if (!get) return refuse(405, "only GET is served outside /api/");
  ApiRequest decoded;
  decoded.kind = Kind::ASSET;
  decoded.asset = request.path;
  return decoded;
}

}  // namespace orthoflow::ui
