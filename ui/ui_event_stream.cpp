#include "ui/ui_event_stream.hpp"

#include "ui/task_link.hpp"

#include <algorithm>
#include <chrono>

#include "ui/background_thread.hpp"
#include "ui/ui_json.hpp"

namespace orthoflow::ui {

namespace {
std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

EventStream::EventStream(UiBackend& backend, double max_hz, std::size_t max_clients, Write write)
    : backend_(backend), max_hz_(max_hz), max_clients_(max_clients), write_(std::move(write)) {
  thread_ = std::thread([this] { run(); });
}

EventStream::~EventStream() {
  {
    std::lock_guard<std::mutex> guard(lock_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool EventStream::add(void* client, double hz, bool camera) {
  {
    std::lock_guard<std::mutex> guard(lock_);
    if (clients_.size() >= max_clients_) return false;
    const double rate = clamp(hz);
    clients_.push_back({client, static_cast<std::int64_t>(1e9 / rate), now_ns(), camera, false});
  }
  wake_.notify_all();
  return true;
}

void EventStream::remove(void* client) {
  std::lock_guard<std::mutex> guard(lock_);
  std::erase_if(clients_, [&](const Client& c) { return c.id == client; });
}

std::size_t EventStream::clients() const {
  std::lock_guard<std::mutex> guard(lock_);
  return clients_.size();
}

std::uint64_t EventStream::sent() const {
  std::lock_guard<std::mutex> guard(lock_);
  return sent_;
}

// One tick: wait until a client is due, make the document without the lock (the backend copies the
// state), then write it to every client due by now. A client's next time advances by its period
// from its previous time, so its rate does not drift with the document's cost.
void EventStream::run() {
  make_this_thread_background();
  std::unique_lock<std::mutex> guard(lock_);
  while (!stop_) {
    bool due = false, camera = false;  // a client is due; one of the due shows the camera
    const std::int64_t tick = now_ns();
    for (const Client& c : clients_) {
      if (c.failed || c.next_ns > tick) continue;
      due = true;
      camera = camera || c.camera;
    }
    if (!due) {
      wake_.wait_for(guard, std::chrono::milliseconds(2));
      continue;
    }
    guard.unlock();
    if (camera) backend_.want_camera();
    const std::string document = state_json(snapshot_with_task(backend_));
    guard.lock();
    const std::int64_t now = now_ns();
    for (Client& c : clients_) {
      if (c.failed || c.next_ns > now) continue;
      c.failed = !write_(c.id, document);
      if (!c.failed) ++sent_;
      c.next_ns += c.period_ns;
      if (c.next_ns <= now) c.next_ns = now + c.period_ns;  // behind: skip, never burst
    }
  }
}

}  // namespace orthoflow::ui
