#include "engine/roudi_watch.hpp"

#include <algorithm>

#include "engine/ipc_runtime.hpp"

namespace orthoflow::engine {

RoudiWatch::RoudiWatch(std::function<void()> on_lost, std::chrono::milliseconds period)
    : on_lost_(std::move(on_lost)), period_(period), thread_([this] { loop(); }) {}

RoudiWatch::~RoudiWatch() {
  stop_.store(true, std::memory_order_release);
  thread_.join();
}

void RoudiWatch::loop() {
  // Sleeps in slices of at most 10 ms so that the destructor never waits a whole period.
  const auto slice = std::min(period_, std::chrono::milliseconds(10));
  auto next = std::chrono::steady_clock::now();
  while (!stop_.load(std::memory_order_acquire)) {
    if (std::chrono::steady_clock::now() >= next) {
      next += period_;
      if (ipc_roudi_lost() || !probe_roudi()) {
        mark_roudi_lost();
        fired_.store(true, std::memory_order_release);
        on_lost_();
        return;
      }
    }
    std::this_thread::sleep_for(slice);
  }
}

}  // namespace orthoflow::engine
