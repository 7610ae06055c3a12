#pragma once
/// @file
/// @brief The injectable monotonic clock of the USB seam (STYLE rule 16): protocol code
/// (control-reply polling, the JACO watchdog, the DSP >= 5 double send, frame-arrival timeouts)
/// reads time only through MonotonicClock, so tests run those timeouts in microseconds with a
/// ManualClock and a simulator can run its devices on simulated time. Header only.
#include <atomic>
#include <chrono>
#include <cstdint>

#include "core/assert.hpp"

namespace orthoflow::drivers {

/// @brief A source of monotonic time in nanoseconds from an arbitrary, fixed origin.
/// @note Implementations must be safe to read from any thread and must never go backwards.
class MonotonicClock {
 public:
  virtual ~MonotonicClock() = default;
  /// @brief Nanoseconds since the clock's origin. @pre none. @note Thread-safe; never decreases.
  [[nodiscard]] virtual std::int64_t now_ns() const noexcept = 0;

 protected:
  MonotonicClock() = default;
  MonotonicClock(const MonotonicClock&) = default;
  MonotonicClock& operator=(const MonotonicClock&) = default;
};

/// @brief The real clock: std::chrono::steady_clock.
/// @note Stateless; thread-safe. Not deterministic (it is wall time).
class SteadyClock final : public MonotonicClock {
 public:
  /// @brief steady_clock's time since its epoch, in ns. @pre none. @note Thread-safe.
  [[nodiscard]] std::int64_t now_ns() const noexcept override {
    const auto since_epoch = std::chrono::steady_clock::now().time_since_epoch();
    return std::chrono::duration_cast<std::chrono::nanoseconds>(since_epoch).count();
  }
};

/// @brief A clock that moves only when told to: tests and simulators advance it by hand.
/// @note Thread-safe (one atomic): a test thread may advance it while a driver thread reads it.
/// Deterministic: now_ns() is exactly the start plus the sum of the advances.
class ManualClock final : public MonotonicClock {
 public:
  /// @brief A clock reading @p start_ns. @pre none.
  explicit ManualClock(std::int64_t start_ns = 0) noexcept : now_ns_(start_ns) {}

  /// @brief The time set so far. @pre none. @note Thread-safe.
  [[nodiscard]] std::int64_t now_ns() const noexcept override {
    return now_ns_.load(std::memory_order_acquire);
  }

  /// @brief Moves the clock forward by @p delta. @pre delta >= 0 (OF_ENFORCE: time never goes
  /// back).
  /// @note Thread-safe.
  void advance(std::chrono::nanoseconds delta) noexcept {
    OF_ENFORCE(delta.count() >= 0, "ManualClock::advance: a monotonic clock cannot go backwards");
    now_ns_.fetch_add(delta.count(), std::memory_order_acq_rel);
  }

  /// @brief Sets the clock to @p t_ns. @pre t_ns >= now_ns() (OF_ENFORCE). @note Thread-safe with
  /// readers; two threads setting it at once is a bug of the test.
  void set_ns(std::int64_t t_ns) noexcept {
    OF_ENFORCE(t_ns >= now_ns(), "ManualClock::set_ns: a monotonic clock cannot go backwards");
    now_ns_.store(t_ns, std::memory_order_release);
  }

 private:
  std::atomic<std::int64_t> now_ns_;
};

}  // namespace orthoflow::drivers
