#include "ui/graph_backend.hpp"

#include <chrono>
#include <cstring>
#include <exception>
#include <thread>

#include "ui/background_thread.hpp"

namespace orthoflow::ui {

namespace {

using Clock = std::chrono::steady_clock;

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
      s.table_reason = latest_->table_reason;
      s.gravity = latest_->gravity;
    }
    s.objects = objects_locked();
  }
  s.events = events_.events();
  for (const learning::CategorySummary& c : learning_.learner().categories()) {
    std::string label(c.label.view());
    const std::int64_t taught = events_.last_taught_ms(label);
    s.memory.push_back({std::move(label), c.views, taught});
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
  return have_latest_ ? object_views(*latest_) : std::vector<ObjectView>{};
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
  events_.record(action, answer);
  return answer;
}

}  // namespace orthoflow::ui
