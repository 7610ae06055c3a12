#include "ui/graph_backend.hpp"

#include <chrono>
#include <cstring>
#include <exception>
#include <thread>

#include "ui/background_thread.hpp"

namespace orthoflow::ui {

namespace {

using Clock = std::chrono::steady_clock;

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

Result<std::unique_ptr<GraphBackend>, std::string> GraphBackend::open(
    graphs::LearningService& learning, graphs::ObjectsHub& hub) {
  auto client = learning.connect();
  if (!client) return err(std::string("the learning channel has no free client slot"));
  return std::unique_ptr<GraphBackend>(
      new GraphBackend(learning, std::move(client), hub.subscribe(4), hub.camera()));
}

GraphBackend::GraphBackend(graphs::LearningService& learning,
                           std::unique_ptr<graphs::LearningClient> client,
                           std::unique_ptr<graphs::ObjectsSubscription> objects,
                           graphs::CameraTap& camera)
    : learning_(learning),
      client_(std::move(client)),
      objects_(std::move(objects)),
      camera_(camera),
      latest_(std::make_unique<engine::ObjectListPayload>()) {
  latest_->reset_header();
  poller_ = std::thread([this] { poll_objects(); });
}

GraphBackend::~GraphBackend() {
  stop_.store(true);
  poller_.join();
}

// Takes the newest list from the subscription's ring into a scratch copy, then swaps it in under
// the lock, so a reader never waits for more than a pointer swap.
void GraphBackend::poll_objects() noexcept {
  make_this_thread_background();  // the camera image is drawn here: the graph goes first
  prepare_camera_fonts();         // now, not at the first image: the graph is warming up
  auto scratch = std::make_unique<engine::ObjectListPayload>();
  while (!stop_.load()) {
    bool got = false;
    while (objects_->poll(*scratch)) got = true;
    if (got) {
      std::lock_guard<std::mutex> guard(state_lock_);
      std::swap(latest_, scratch);
      have_latest_ = true;
    }
    try {
      draw_camera();
    } catch (const std::exception&) {  // out of memory for an image: the page keeps the last one
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

UiSnapshot GraphBackend::snapshot() const {
  UiSnapshot s;
  s.durable = durable();
  {
    std::lock_guard<std::mutex> guard(state_lock_);
    if (have_latest_) {
      s.frame_id = latest_->frame_id;
      s.age_ns = latest_->age_ns;
    }
    s.objects = objects_locked();
    s.events.assign(events_.begin(), events_.end());
    for (const learning::CategorySummary& c : learning_.learner().categories()) {
      const std::string label(c.label.view());
      const auto it = last_taught_ms_.find(label);
      s.memory.push_back({label, c.views, it == last_taught_ms_.end() ? 0 : it->second});
    }
  }
  {
    std::lock_guard<std::mutex> guard(camera_lock_);
    if (!camera_png_.empty()) {  // an image is there to fetch; boxes when its camera is known
      s.camera.frame_id = camera_image_.frame_id;
      s.camera.width = camera_image_.width;
      s.camera.height = camera_image_.height;
      for (const ImageBox& b :
           project_boxes(camera_fit_, camera_image_.width, camera_image_.height, s.objects))
        s.camera.boxes.push_back({b.track, b.u0, b.v0, b.u1, b.v1});
    }
  }
  add_telemetry(s);
  return s;
}

// Asking keeps the tap copying (at most 5 images per second, the rate the page asks at) for the
// next 3 s; the poller thread draws each new image.
void GraphBackend::want_camera() {
  constexpr std::int64_t KEEP_NS = 3'000'000'000;
  camera_.request(Clock::now().time_since_epoch().count(), 200'000'000, KEEP_NS);
}

// A program's first request waits up to 300 ms for the first image.
std::string GraphBackend::camera_png() {
  want_camera();
  std::unique_lock<std::mutex> guard(camera_lock_);
  camera_drawn_.wait_for(guard, std::chrono::milliseconds(300),
                         [this] { return !camera_png_.empty(); });
  return camera_png_;
}

// On the poller thread (a full-size stack: fontconfig, which cairo's text needs, recurses deeply
// when it first reads its configuration, too deeply for the server's small worker stacks).
void GraphBackend::draw_camera() {
  if (!camera_.wanted(Clock::now().time_since_epoch().count())) return;
  graphs::CameraImage image;
  if (!camera_.take(image, camera_taken_)) return;
  camera_taken_ = image.frame_id;  // tried once, drawn or not
  const PinholeFit fit = fit_pinhole(image);
  std::string png = render_camera_png(image, snapshot_objects());
  if (png.empty()) return;  // not drawn: keep the last image, its camera and its PNG together
  std::lock_guard<std::mutex> guard(camera_lock_);
  camera_image_ = std::move(image);
  camera_fit_ = fit;
  camera_png_ = std::move(png);
  camera_drawn_.notify_all();
}

std::vector<ObjectView> GraphBackend::snapshot_objects() const {
  std::lock_guard<std::mutex> guard(state_lock_);
  return objects_locked();
}

std::vector<ObjectView> GraphBackend::objects_locked() const {
  std::vector<ObjectView> objects;
  if (!have_latest_) return objects;
  const std::uint32_t n = std::min(latest_->count, engine::OBJECT_LIST_CAPACITY);
  for (std::uint32_t k = 0; k < n; ++k) objects.push_back(view_of(latest_->objects[k]));
  return objects;
}

void GraphBackend::add_telemetry(UiSnapshot& s) const {
  const engine::GraphStats* stats = stats_.load();
  if (stats == nullptr) return;
  s.frames_done = stats->frames_done.load();
  s.drops = stats->total_drops();
  s.frame_p99_ns = stats->frame_latency.percentile(0.99);
  for (const engine::NodeStats& n : stats->nodes) {
    s.nodes.push_back({n.name, n.processed.load(), n.dropped.load(), n.deadline_misses.load(),
                       n.service.percentile(0.5), n.service.percentile(0.99), n.service.max()});
  }
}

UiAnswer GraphBackend::submit(const UiAction& action, int timeout_ms) {
  UiAnswer answer;
  {
    std::lock_guard<std::mutex> guard(client_lock_);
    graphs::LearningCommand command;
    command.kind = action.kind;
    command.track_id = action.track;
    command.label = action.label;
    const std::uint64_t sequence = client_->send(command);
    if (sequence == 0) {
      answer.status = UiAnswer::Status::QUEUE_FULL;
    } else {
      // Acks of earlier actions that timed out arrive late: skipped by their sequence number.
      const auto deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
      while (answer.status == UiAnswer::Status::TIMEOUT && Clock::now() < deadline) {
        graphs::LearningAck ack;
        while (client_->poll(ack)) {
          if (ack.sequence == sequence) {
            answer = {UiAnswer::Status::ACKNOWLEDGED, ack};
            break;
          }
        }
        if (answer.status == UiAnswer::Status::TIMEOUT)
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    }
  }
  record(action, answer);
  return answer;
}

void GraphBackend::record(const UiAction& action, const UiAnswer& answer) {
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
  std::lock_guard<std::mutex> guard(state_lock_);
  e.id = next_event_++;
  if (ok && (action.kind == Kind::TEACH || action.kind == Kind::CORRECT))
    last_taught_ms_[e.label] = e.time_ms;
  if (ok && action.kind == Kind::FORGET) last_taught_ms_.erase(e.label);
  events_.push_back(std::move(e));
  if (events_.size() > MAX_UI_EVENTS) events_.pop_front();
}

}  // namespace orthoflow::ui
