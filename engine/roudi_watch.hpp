#pragma once
/// @file
/// @brief RoudiWatch: while a graph with IPC nodes runs, a thread probes RouDi at a fixed period
/// and reports a lost RouDi once (mark_roudi_lost() and a callback, e.g. Engine::request_stop), so
/// that a run ends within a bounded time even when no IPC node is busy (a publisher between frames,
/// a subscriber waiting for data). See docs/IPC.md, "Safety against iceoryx 2.0.3's aborts".
#include <atomic>
#include <chrono>
#include <functional>
#include <thread>

namespace orthoflow::engine {

/// @brief Probes RouDi (probe_roudi(): a socket connect, microseconds) every `period` from its own
/// thread; on the first failed probe, or once an IPC node has called mark_roudi_lost(), it marks
/// RouDi lost and calls `on_lost` once, from that thread. Destroying it stops and joins the thread
/// (within one period).
/// @pre `on_lost` is thread-safe and outlives the watch. Start-up only (starts a thread).
/// @note The probe never blocks, so every wait here is bounded by `period`.
class RoudiWatch {
 public:
  explicit RoudiWatch(std::function<void()> on_lost,
                      std::chrono::milliseconds period = std::chrono::milliseconds(50));
  ~RoudiWatch();
  RoudiWatch(const RoudiWatch&) = delete;
  RoudiWatch& operator=(const RoudiWatch&) = delete;

  /// @brief True once this watch saw RouDi lost (and called `on_lost`). Thread-safe.
  [[nodiscard]] bool fired() const noexcept { return fired_.load(std::memory_order_acquire); }

 private:
  void loop();
  std::function<void()> on_lost_;
  std::chrono::milliseconds period_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> fired_{false};
  std::thread thread_;
};

}  // namespace orthoflow::engine
