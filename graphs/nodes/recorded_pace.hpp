#pragma once
/// @file
/// @brief (internal) RecordedPace: emits a recording's frames at the pace they were recorded
/// (replay_source, tum_source): each frame waits until its time since the first frame, a pause of
/// more than a second in the recording is cut to one second, and a schedule that goes back (a
/// loop starting over) restarts the clock.
#include <chrono>
#include <cstdint>
#include <thread>

namespace orthoflow::graphs {

class RecordedPace {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::int64_t MAX_GAP_NS = 1'000'000'000;

  /// Sleeps until @p schedule_ns (the frame's recorded time since the first frame) has come.
  void wait(std::int64_t schedule_ns) noexcept {
    const auto now = Clock::now();
    if (!started_ || schedule_ns < last_schedule_ns_) {
      started_ = true;
      origin_ = now - std::chrono::nanoseconds(schedule_ns);
    } else if (schedule_ns - last_schedule_ns_ > MAX_GAP_NS) {
      origin_ -= std::chrono::nanoseconds(schedule_ns - last_schedule_ns_ - MAX_GAP_NS);
    }
    last_schedule_ns_ = schedule_ns;
    std::this_thread::sleep_until(origin_ + std::chrono::nanoseconds(schedule_ns));
  }

 private:
  bool started_ = false;
  std::int64_t last_schedule_ns_ = 0;
  Clock::time_point origin_{};
};

}  // namespace orthoflow::graphs
