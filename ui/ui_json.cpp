#include "ui/ui_json.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <string_view>

#include "engine/object_list_payload.hpp"
#include "graphs/frame/frame_block.hpp"
#include "kernels/table_verdict.hpp"

namespace orthoflow::ui {

namespace {

using Json = nlohmann::json;
using Outcome = graphs::LearningAck::Outcome;

Json number_or_null(float v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json vec3(const float (&v)[3]) {
  return Json::array({number_or_null(v[0]), number_or_null(v[1]), number_or_null(v[2])});
}

Json object_json(const ObjectView& o) {
  return {{"track", o.track_id},
          {"label", o.unknown ? Json(nullptr) : Json(o.label)},
          {"score", number_or_null(o.score)},
          {"centroid", vec3(o.centroid)},
          {"bbox_min", vec3(o.bbox_min)},
          {"bbox_max", vec3(o.bbox_max)},
          {"points", o.point_count},
          {"described", (o.flags & engine::OBJECT_DESCRIBED) != 0},
          {"moving", (o.flags & engine::OBJECT_MOVING) != 0},
          {"fragment", (o.flags & engine::OBJECT_FRAGMENT) != 0}};
}

Json event_json(const EventView& e) {
  return {{"id", e.id},       {"time_ms", e.time_ms}, {"action", e.action},
          {"track", e.track}, {"label", e.label},     {"outcome", e.outcome},
          {"ok", e.ok},       {"views", e.views},     {"frame", e.frame_id}};
}

Json telemetry_json(const UiSnapshot& s) {
  Json nodes = Json::array();
  for (const NodeLatency& n : s.nodes) {
    nodes.push_back({{"name", n.name},
                     {"processed", n.processed},
                     {"dropped", n.dropped},
                     {"deadline_misses", n.deadline_misses},
                     {"p50_us", static_cast<double>(n.p50_ns) * 1e-3},
                     {"p99_us", static_cast<double>(n.p99_ns) * 1e-3},
                     {"max_us", static_cast<double>(n.max_ns) * 1e-3}});
  }
  return {{"frames", s.frames_done},
          {"drops", s.drops},
          {"frame_p99_us", static_cast<double>(s.frame_p99_ns) * 1e-3},
          {"nodes", std::move(nodes)}};
}

// What a refused action means, for the person who asked (the outcome names it for programs).
std::string_view refusal_text(Outcome outcome) {
  switch (outcome) {
    case Outcome::NO_SUCH_TRACK:
      return "no object with that track in the current frame (it left the view)";
    case Outcome::NOT_DESCRIBED:
      return "the object has no descriptor in this frame (too few points); try again";
    case Outcome::BAD_LABEL:
      return "the label is empty or too long";
    case Outcome::REJECTED:
      return "the learner refused the object's views (not finite, or the wrong length)";
    case Outcome::UNKNOWN_LABEL:
      return "no category of that name in the memory";
    case Outcome::WRITE_FAILED:
      return "the memory could not be written: nothing was stored";
    case Outcome::BUSY:
      return "the memory's writer is behind: nothing was stored; send again";
    case Outcome::NOTHING_TO_UNDO:
      return "no lesson left to undo (or the memory changed since)";
    case Outcome::STORED:
    case Outcome::LEARNED:
    case Outcome::ANSWERED:
      break;
  }
  return "refused";
}

// The objects' boxes in the last camera image, or null before one was served.
/// The frame's table verdict (docs/SEGMENTATION.md, "The table verdict"): null when not reported.
Json table_json(const UiSnapshot& s) {
  using kernels::TableReason;
  if (s.table_reason == 0 || s.table_reason > static_cast<unsigned>(TableReason::TOO_SMALL) + 1U)
    return nullptr;
  const auto reason = static_cast<TableReason>(s.table_reason - 1U);
  const bool known_gravity =
      s.gravity >= 1 && s.gravity <= static_cast<unsigned>(graphs::Gravity::CONFIGURED) + 1U;
  return {{"found", reason == TableReason::ACCEPTED || reason == TableReason::HELD},
          {"reason", kernels::table_reason_name(reason)},
          {"gravity", known_gravity
                          ? Json(graphs::gravity_name(static_cast<graphs::Gravity>(s.gravity - 1U)))
                          : Json(nullptr)}};
}

Json camera_json(const CameraBoxes& c) {
  if (c.frame_id == 0) return nullptr;
  Json boxes = Json::array();
  for (const CameraBoxes::Box& b : c.boxes)
    boxes.push_back({{"track", b.track}, {"box", Json::array({b.u0, b.v0, b.u1, b.v1})}});
  return {
      {"frame", c.frame_id}, {"width", c.width}, {"height", c.height}, {"boxes", std::move(boxes)}};
}

}  // namespace

nlohmann::json task_status_json(const graphs::TaskStatus& t) {
  return {{"state", graphs::to_string(t.state)},
          {"task", manipulation::to_string(t.task)},
          {"answer", graphs::to_string(t.answer)},
          {"move", t.move},
          {"moves", t.moves},
          {"done", t.done},
          {"phase", manipulation::to_string(t.phase)},
          {"message", t.message}};
}

std::string task_answer_json(const graphs::TaskCommand& command, const graphs::TaskStatus& answer) {
  const bool ok =
      answer.answer == graphs::TaskAnswer::STARTED || answer.answer == graphs::TaskAnswer::STOPPING;
  Json doc = task_status_json(answer);
  doc["ok"] = ok;
  doc["action"] = graphs::to_string(command.kind);
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace);
}

namespace {

Json task_view_json(const UiSnapshot& s) {
  if (!s.task) return nullptr;
  Json doc = task_status_json(*s.task);
  doc["age_ms"] = s.task_age_ms;
  return doc;
}

}  // namespace

std::string state_json(const UiSnapshot& s) {
  Json objects = Json::array(), memory = Json::array(), events = Json::array();
  for (const ObjectView& o : s.objects) objects.push_back(object_json(o));
  for (const CategoryView& c : s.memory) {
    memory.push_back(
        {{"label", c.label},
         {"views", c.views},
         {"last_taught_ms", c.last_taught_ms == 0 ? Json(nullptr) : Json(c.last_taught_ms)}});
  }
  for (const EventView& e : s.events) events.push_back(event_json(e));
  const Json doc = {{"frame", s.frame_id},
                    {"age_ms", static_cast<double>(s.age_ns) * 1e-6},
                    {"table", table_json(s)},
                    {"durable", s.durable},
                    {"objects", std::move(objects)},
                    {"memory", std::move(memory)},
                    {"events", std::move(events)},
                    {"telemetry", telemetry_json(s)},
                    {"camera", camera_json(s.camera)},
                    {"tasks", s.task_control},
                    {"task", task_view_json(s)}};
  // Labels are valid UTF-8 by the label rule; replace keeps a bad byte from throwing regardless.
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace);
}

int http_status(const UiAnswer& answer) noexcept {
  if (answer.status == UiAnswer::Status::QUEUE_FULL) return 503;
  if (answer.status == UiAnswer::Status::TIMEOUT) return 504;
  switch (answer.ack.outcome) {
    case Outcome::STORED:
    case Outcome::LEARNED:
    case Outcome::ANSWERED:
      return 200;
    case Outcome::NO_SUCH_TRACK:
    case Outcome::UNKNOWN_LABEL:
      return 404;
    case Outcome::BAD_LABEL:
      return 400;
    case Outcome::NOT_DESCRIBED:
    case Outcome::NOTHING_TO_UNDO:
      return 409;
    case Outcome::REJECTED:
      return 422;
    case Outcome::WRITE_FAILED:
      return 500;
    case Outcome::BUSY:
      return 503;
  }
  return 500;
}

std::string answer_json(const UiAction& action, const UiAnswer& answer, bool durable) {
  using Kind = graphs::LearningCommand::Kind;
  const bool acked = answer.status == UiAnswer::Status::ACKNOWLEDGED;
  const bool ok = acked && answer.ack.ok();
  Json doc = {{"ok", ok}, {"action", graphs::to_string(action.kind)}, {"durable", durable}};
  doc["outcome"] = acked ? std::string(graphs::to_string(answer.ack.outcome))
                   : answer.status == UiAnswer::Status::QUEUE_FULL ? "queue_full"
                                                                   : "timeout";
  if (acked) {
    doc["track"] = answer.ack.track_id;
    doc["frame"] = answer.ack.frame_id;
    doc["views"] = answer.ack.views;
  }
  if (action.kind == Kind::ASK && ok) {
    doc["answer"] = answer.ack.unknown ? Json(nullptr) : Json(std::string(answer.ack.label.view()));
    doc["score"] = number_or_null(answer.ack.score);
    // The learner's nearest categories, each with its decision value: the best one (also when the
    // answer is Unknown), then the runner-up.
    Json nearest = Json::array();
    if (!answer.ack.nearest.empty())
      nearest.push_back({{"label", std::string(answer.ack.nearest.view())},
                         {"score", number_or_null(answer.ack.score)}});
    if (!answer.ack.runner_up.empty())
      nearest.push_back({{"label", std::string(answer.ack.runner_up.view())},
                         {"score", number_or_null(answer.ack.runner_up_score)}});
    doc["nearest"] = std::move(nearest);
  } else if (action.kind == Kind::UNDO) {
    doc["label"] = acked && !answer.ack.label.empty() ? Json(std::string(answer.ack.label.view()))
                                                      : Json(nullptr);
  } else if (action.kind != Kind::ASK) {
    doc["label"] = std::string(action.label.view());
  }
  if (!ok) {
    doc["error"] = !acked ? (answer.status == UiAnswer::Status::QUEUE_FULL
                                 ? "the learning channel is full; send again"
                                 : "no acknowledgement in time (is the graph running?)")
                          : std::string(refusal_text(answer.ack.outcome));
  }
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace);
}

std::string error_json(const ApiError& error) {
  const Json doc = {{"error", error.message}, {"status", error.status}};
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace orthoflow::ui
