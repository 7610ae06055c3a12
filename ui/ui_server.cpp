#include "ui/ui_server.hpp"

#include "ui/task_link.hpp"

#include <civetweb.h>

#include <chrono>
#include <string_view>
#include <vector>

#include "ui/background_thread.hpp"
#include "ui/http_reply.hpp"
#include "ui/ui_assets.hpp"
#include "ui/ui_json.hpp"

namespace orthoflow::ui {

namespace {

using Kind = ApiRequest::Kind;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The request as the pure checks see it; @p headers keeps the views alive.
RawRequest raw_request(const mg_request_info* ri, std::vector<HttpHeader>& headers) {
  headers.clear();
  for (int i = 0; i < ri->num_headers; ++i)
    headers.push_back({ri->http_headers[i].name, ri->http_headers[i].value});
  RawRequest raw;
  raw.method = ri->request_method != nullptr ? ri->request_method : "";
  // The decoded path as sent (not civetweb's cleaned local_uri): assets match exactly or not at
  // all.
  const char* path = ri->local_uri_raw != nullptr ? ri->local_uri_raw : ri->request_uri;
  raw.path = path != nullptr ? path : "";
  raw.query = ri->query_string != nullptr ? ri->query_string : "";
  raw.headers = headers;
  return raw;
}

// Reads the body, at most MAX_BODY_BYTES + 1 bytes (one more tells decode_request it is too large).
std::string read_body(mg_connection* conn, long long declared) {
  std::string body;
  const std::size_t cap = MAX_BODY_BYTES + 1;
  if (declared == 0) return body;
  char chunk[4096];
  while (body.size() < cap) {
    const int n = mg_read(conn, chunk, std::min(sizeof chunk, cap - body.size()));
    if (n <= 0) break;
    body.append(chunk, static_cast<std::size_t>(n));
  }
  return body;
}

// Every path goes to handle_http; /api/events upgrades to a WebSocket stream.
void register_handlers(mg_context* ctx, UiServer* s) {
  mg_set_request_handler(
      ctx, "/",
      [](mg_connection* c, void* self) { return static_cast<UiServer*>(self)->handle_http(c); }, s);
  mg_set_websocket_handler(
      ctx, "/api/events",
      [](const mg_connection* c, void* self) {
        return static_cast<UiServer*>(self)->ws_connect(c);
      },
      [](mg_connection* c, void* self) { static_cast<UiServer*>(self)->ws_ready(c); },
      [](mg_connection*, int opcode, char*, std::size_t, void*) {
        return (opcode & 0xF) == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE ? 0 : 1;
      },
      [](const mg_connection* c, void* self) { static_cast<UiServer*>(self)->ws_close(c); }, s);
}

}  // namespace

UiServer::UiServer(UiServerConfig config, UiBackend& backend)
    : config_(std::move(config)), backend_(backend), limiter_(config_.rate) {}

Result<std::unique_ptr<UiServer>, std::string> UiServer::start(UiServerConfig config,
                                                               UiBackend& backend) {
  mg_init_library(MG_FEATURES_WEBSOCKET);
  if (mg_check_feature(MG_FEATURES_WEBSOCKET) == 0)
    return err(std::string("this civetweb was built without WebSocket support"));
  if (config.token.empty() && !is_loopback_address(config.address)) config.token = generate_token();
  std::unique_ptr<UiServer> server(new UiServer(std::move(config), backend));
  UiServer* s = server.get();
  s->stream_ = std::make_unique<EventStream>(
      backend, s->config_.max_stream_hz, s->config_.max_stream_clients,
      [](void* client, std::string_view text) {
        return mg_websocket_write(static_cast<mg_connection*>(client), MG_WEBSOCKET_OPCODE_TEXT,
                                  text.data(), text.size()) > 0;
      });
  const std::string ports = s->config_.address + ":" + std::to_string(s->config_.port);
  // A WebSocket holds its worker thread while it lives: streams get threads of their own.
  const std::string threads =
      std::to_string(s->config_.threads + s->config_.max_stream_clients + 1);
  // civetweb answers a CORS preflight itself ("*") unless the access_control_* options are empty:
  // the API is same-origin only (docs/UI.md), so no preflight is ever granted.
  // clang-format off
  const char* options[] = {
      "listening_ports", ports.c_str(),
      "num_threads", threads.c_str(),
      "request_timeout_ms", "10000",
      "enable_websocket_ping_pong", "yes",
      "websocket_timeout_ms", "30000",
      "access_control_allow_origin", "",
      "access_control_allow_methods", "",
      "access_control_allow_headers", "",
      nullptr};
  // clang-format on
  mg_callbacks callbacks{};
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };  // answered here
  callbacks.init_thread = [](const mg_context*, int) -> void* {  // master, workers, timer
    make_this_thread_background();
    return nullptr;
  };
  s->ctx_ = mg_start(&callbacks, s, options);
  if (s->ctx_ == nullptr) return err("cannot listen on " + ports + " (in use, or no such address)");
  mg_server_port bound[4]{};
  if (mg_get_server_ports(s->ctx_, 4, bound) < 1) return err("no listening port after start");
  s->port_ = static_cast<std::uint16_t>(bound[0].port);
  s->policy_ = make_access_policy(s->config_.address, s->port_, s->config_.token);
  s->cookie_ = token_cookie(s->policy_);
  register_handlers(s->ctx_, s);
  return server;
}

UiServer::~UiServer() {
  if (ctx_ != nullptr) mg_stop(ctx_);  // closes the streams (ws_close) before the stream goes
  stream_.reset();
  mg_exit_library();
}

std::string UiServer::url() const {
  // Never with the token: the URL is printed, and a service's output goes to the journal.
  return "http://" + config_.address + ":" + std::to_string(port_) + "/";
}

int UiServer::handle_http(mg_connection* conn) {
  const mg_request_info* ri = mg_get_request_info(conn);
  if (!limiter_.allow(ri->remote_addr, now_ns()))
    return reply_error(conn, {429, "too many requests"}, extra_headers_for(429));
  std::vector<HttpHeader> headers;
  RawRequest raw = raw_request(ri, headers);
  if (auto denied = check_access(policy_, raw))
    return reply_error(conn, *denied, extra_headers_for(denied->status));
  if (ri->content_length > static_cast<long long>(MAX_BODY_BYTES))
    return reply_error(conn, {413, "the body is larger than 16384 bytes"});
  const std::string body = read_body(conn, ri->content_length);
  raw.body = body;
  auto request_result = decode_request(raw);
  if (!request_result) return reply_error(conn, request_result.error());
  return serve(conn, *request_result);
}

int UiServer::serve(mg_connection* conn, const ApiRequest& request) {
  switch (request.kind) {
    case Kind::STATE:
      return reply(conn, 200, "application/json", state_json(snapshot_with_task(backend_)));
    case Kind::EVENTS:
      return reply_error(conn, {426, "GET /api/events is a WebSocket: send an Upgrade"},
                         "Upgrade: websocket\r\n");
    case Kind::CAMERA: {
      const std::string png = backend_.camera_png();
      if (png.empty())
        return reply_error(
            conn, {404, "no camera image (no frame yet, or the source has no pixel grid)"});
      return reply(conn, 200, "image/png", png);
    }
    case Kind::ASSET:
      if (const Asset* asset = find_asset(request.asset); asset != nullptr) {
        // The page, loaded with the token, hands its browser the token cookie: the browser then
        // sends it with the page's script and style requests, which carry no ?token=.
        const bool page = std::string_view(asset->content_type).starts_with("text/html");
        return reply(conn, 200, asset->content_type, asset->text(), page ? cookie_.c_str() : "");
      }
      return reply_error(conn, {404, "no such page"});
    case Kind::TASK_START:
    case Kind::TASK_STOP:
      return act_task(conn, request);
    case Kind::ARM_STOP:
      return act_arm_stop(conn);
    default:
      return act(conn, request);
  }
}

int UiServer::act_task(mg_connection* conn, const ApiRequest& request) {
  TaskLink* link = backend_.task_link();
  if (link == nullptr)
    return reply_error(conn, {503,
                              "no task control here: run the graph with --ipc-learning (or "
                              "`orthoflow ui`) beside `orthoflow task run`"});
  const TaskReply answered = link->send(request.task, config_.ack_timeout_ms);
  switch (answered.status) {
    case TaskReply::Status::NO_TASK_PROCESS:
      return reply_error(conn, {503, "no `orthoflow task run` takes task commands"});
    case TaskReply::Status::TIMEOUT:
      return reply_error(conn, {504, "`orthoflow task run` did not answer"});
    case TaskReply::Status::INVALID:
      return reply_error(conn, {400, "a category is not a valid label"});
    case TaskReply::Status::ANSWERED:
      break;
  }
  const graphs::TaskAnswer a = answered.answer.answer;
  const int status = a == graphs::TaskAnswer::STARTED || a == graphs::TaskAnswer::STOPPING ? 200
                     : a == graphs::TaskAnswer::REFUSED                                    ? 409
                                                                                           : 400;
  return reply(conn, status, "application/json", task_answer_json(request.task, answered.answer));
}

// The stop button: the holder halts the arm in place and latches it; 503 when nobody holds one.
int UiServer::act_arm_stop(mg_connection* conn) {
  TaskLink* link = backend_.task_link();
  if (link == nullptr)
    return reply_error(conn, {503,
                              "no arm control here: run the graph with --ipc-learning (or "
                              "`orthoflow ui`) beside the process holding the arm"});
  const ArmStopReply r = link->stop_arm(config_.ack_timeout_ms);
  if (r.status == ArmStopReply::Status::NO_HOLDER)
    return reply_error(conn, {503, "no process holding an arm listens for stops"});
  if (r.status == ArmStopReply::Status::TIMEOUT)
    return reply_error(conn, {504, "the process holding the arm did not confirm the stop"});
  const nlohmann::json out = {{"ok", true},
                              {"stopped", true},
                              {"latched", true},
                              {"was_moving", r.was_moving},
                              {"holder", r.holder},
                              {"holder_pid", r.holder_pid},
                              {"request_to_halt_ms", r.request_to_halt_ms}};
  return reply(conn, 200, "application/json", out.dump());
}

int UiServer::act(mg_connection* conn, const ApiRequest& request) {
  UiAction action;
  action.kind = request.kind == Kind::TEACH     ? graphs::LearningCommand::Kind::TEACH
                : request.kind == Kind::CORRECT ? graphs::LearningCommand::Kind::CORRECT
                : request.kind == Kind::ASK     ? graphs::LearningCommand::Kind::ASK
                : request.kind == Kind::UNDO    ? graphs::LearningCommand::Kind::UNDO
                                                : graphs::LearningCommand::Kind::FORGET;
  action.track = request.track;
  action.label = request.label;
  const UiAnswer answer = backend_.submit(action, config_.ack_timeout_ms);
  return reply(conn, http_status(answer), "application/json",
               answer_json(action, answer, backend_.durable()));
}

// The upgrade passes the same checks as any request; a refused one gets its status here, since
// civetweb only drops the connection when this returns non-zero.
int UiServer::ws_connect(const mg_connection* conn) {
  auto* writable = const_cast<mg_connection*>(conn);  // civetweb's own connection, its thread
  const mg_request_info* ri = mg_get_request_info(conn);
  if (!limiter_.allow(ri->remote_addr, now_ns())) {
    reply_error(writable, {429, "too many requests"}, extra_headers_for(429));
    return 1;
  }
  std::vector<HttpHeader> headers;
  const RawRequest raw = raw_request(ri, headers);
  if (auto denied = check_access(policy_, raw)) {
    reply_error(writable, *denied, extra_headers_for(denied->status));
    return 1;
  }
  auto request_result = decode_request(raw);
  if (!request_result) {
    reply_error(writable, request_result.error());
    return 1;
  }
  if (stream_->clients() >= config_.max_stream_clients) {
    reply_error(writable, {503, "too many streams"});
    return 1;
  }
  return 0;
}

void UiServer::ws_ready(mg_connection* conn) {
  std::vector<HttpHeader> headers;
  const auto request_result = decode_request(raw_request(mg_get_request_info(conn), headers));
  const double hz = request_result ? request_result->hz : DEFAULT_STREAM_HZ;
  const bool camera = request_result && request_result->camera;
  if (stream_->add(conn, hz, camera))
    mg_set_user_connection_data(conn, conn);  // marks it as streaming
}

void UiServer::ws_close(const mg_connection* conn) {
  if (mg_get_user_connection_data(conn) != nullptr)
    stream_->remove(const_cast<mg_connection*>(conn));
}

}  // namespace orthoflow::ui
