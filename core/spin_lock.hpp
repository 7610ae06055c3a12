#pragma once
/// @file
/// @brief SpinLock: a tiny test-and-test-and-set lock for critical sections of a few dozen
/// instructions (copying one fixed-size record into a ring), where a frame-path thread must never
/// be parked by the scheduler as a std::mutex may do. Meets the Lockable requirements
/// (std::lock_guard works).
#include <atomic>
#include <thread>

namespace orthoflow::core {

/// @note Use only around short, bounded, non-blocking sections; never hold it across I/O or
/// allocation.
class SpinLock {
 public:
  void lock() noexcept {
    while (flag_.exchange(true, std::memory_order_acquire)) {
      while (flag_.load(std::memory_order_relaxed)) std::this_thread::yield();
    }
  }
  [[nodiscard]] bool try_lock() noexcept {
    return !flag_.exchange(true, std::memory_order_acquire);
  }
  void unlock() noexcept { flag_.store(false, std::memory_order_release); }

 private:
  std::atomic<bool> flag_{false};
};

}  // namespace orthoflow::core
