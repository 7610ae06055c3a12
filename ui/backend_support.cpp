#include "ui/backend_support.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <random>

namespace orthoflow::ui {

namespace {

std::int64_t unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

ObjectView view_of(const engine::ObjectEntry& e) {
  ObjectView o;
  o.track_id = e.track_id;
  o.unknown = e.unknown != 0;
  o.label = o.unknown ? std::string{} : std::string(e.label.view());
  o.score = e.score;
  std::memcpy(o.centroid, e.centroid, sizeof o.centroid);
  std::memcpy(o.bbox_min, e.bbox_min, sizeof o.bbox_min);
  std::memcpy(o.bbox_max, e.bbox_max, sizeof o.bbox_max);
  o.point_count = e.point_count;
  o.flags = e.flags;
  return o;
}

std::string outcome_text(const UiAnswer& a) {
  switch (a.status) {
    case UiAnswer::Status::ACKNOWLEDGED:
      return std::string(graphs::to_string(a.ack.outcome));
    case UiAnswer::Status::QUEUE_FULL:
      return "queue_full";
    case UiAnswer::Status::TIMEOUT:
      return "timeout";
  }
  return "?";
}

}  // namespace

std::uint64_t random_client_id() {
  std::random_device device;
  std::uint64_t id = 0;
  while (id == 0) id = (std::uint64_t{device()} << 32U) ^ device();
  return id;
}

std::vector<ObjectView> object_views(const engine::ObjectListPayload& list) {
  std::vector<ObjectView> objects;
  const std::uint32_t n = std::min(list.count, engine::OBJECT_LIST_CAPACITY);
  for (std::uint32_t k = 0; k < n; ++k) objects.push_back(view_of(list.objects[k]));
  return objects;
}

void EventLog::record(const UiAction& action, const UiAnswer& answer) {
  using Kind = graphs::LearningCommand::Kind;
  const bool ok = answer.status == UiAnswer::Status::ACKNOWLEDGED && answer.ack.ok();
  EventView e;
  e.time_ms = unix_ms();
  e.action = std::string(graphs::to_string(action.kind));
  e.track = ok && action.kind != Kind::FORGET && action.kind != Kind::UNDO ? answer.ack.track_id
                                                                           : action.track;
  e.label = action.kind == Kind::ASK || action.kind == Kind::UNDO
                ? std::string(answer.ack.label.view())
                : std::string(action.label.view());
  e.outcome = outcome_text(answer);
  e.ok = ok;
  e.views = answer.ack.views;
  e.frame_id = answer.ack.frame_id;
  std::lock_guard<std::mutex> guard(lock_);
  e.id = next_event_++;
  if (ok && (action.kind == Kind::TEACH || action.kind == Kind::CORRECT))
    last_taught_ms_[e.label] = e.time_ms;
  if (ok && action.kind == Kind::FORGET) last_taught_ms_.erase(e.label);
  events_.push_back(std::move(e));
  if (events_.size() > MAX_UI_EVENTS) events_.pop_front();
}

std::vector<EventView> EventLog::events() const {
  std::lock_guard<std::mutex> guard(lock_);
  return {events_.begin(), events_.end()};
}

std::int64_t EventLog::last_taught_ms(const std::string& label) const {
  std::lock_guard<std::mutex> guard(lock_);
  const auto it = last_taught_ms_.find(label);
  return it == last_taught_ms_.end() ? 0 : it->second;
}

}  // namespace orthoflow::ui
