#pragma once
/// @file
/// @brief JacoArm: a JacoController with its three threads (issues 19 and 49, docs/SAFETY.md):
/// - the USB thread owns the transport and runs cycle() every 10 ms of the transport's clock;
/// - the guard thread runs guard() every GUARD_PERIOD_NS and never touches USB: it declares a
///   silent arm FAULT, turns a stop signal (request_signal_stop) into the latched stop, and runs
///   with SCHED_FIFO where the process may (realtime_guard() says whether it got it);
/// - the notifier thread hands each cycle's snapshot to the subscribers (the 100 Hz state stream),
///   so a slow subscriber never delays the control loop.
/// Clients on any thread submit commands, feed the watchdog and stop the arm.
///
/// With a state directory (arm_state_dir.hpp) the arm is held for as long as this object lives (a
/// second holder is refused, naming this one), every stop is latched there with its reason, and an
/// arm latched by an earlier process starts latched: it moves again only after a person resets it.
///
/// Simulated time: with `pace_to_wall_clock`, the USB thread keeps a simulator's clock no faster
/// than wall time, so the simulated arm moves as fast as a real one (the CLI's --sim); without it
/// the simulation runs as fast as the CPU allows (tests), and client threads must then read time
/// from the transport's clock.
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "drivers/jaco/arm_state_dir.hpp"
#include "drivers/jaco/jaco_controller.hpp"

namespace orthoflow::drivers::jaco {

/// @brief Called on the notifier thread after every cycle. Must not throw.
using StateCallback = std::function<void(const ArmSnapshot&)>;

/// @brief The guard's period.
inline constexpr std::int64_t GUARD_PERIOD_NS = 2'000'000;

struct ArmOptions {
  ControllerOptions controller{};
  bool pace_to_wall_clock = false;
  std::vector<StateCallback> subscribers{};  ///< fixed before start
  std::string state_dir;                     ///< empty: no holding, no persistent latch (tests)
  std::string holder = "orthoflow";          ///< what the holder file says this process is
};

/// @brief Asks every JacoArm of this process to latch its stop, with @p signal_number as the
/// reason; every request latches anew (after a reset). Async-signal-safe (lock-free atomics): for
/// SIGINT / SIGTERM / SIGHUP / SIGQUIT handlers.
void request_signal_stop(int signal_number) noexcept;
/// @brief The signal a handler asked to stop for (0: none). @pre none.
[[nodiscard]] int signal_stop_requested() noexcept;
/// @brief Installs request_signal_stop as the handler of SIGINT, SIGTERM, SIGHUP and SIGQUIT.
void install_stop_signals() noexcept;

class JacoArm {
 public:
  /// @brief Holds the arm (when a state directory is given), opens @p device on @p transport (on
  /// the calling thread), then starts the threads. @return the start-up error (a sentence for a
  /// state directory held by another process: JacoError::BUSY with its text in busy_reason()).
  [[nodiscard]] static Result<std::unique_ptr<JacoArm>, JacoError> start(
      std::unique_ptr<UsbTransport> transport, const UsbDeviceInfo& device, ArmOptions options,
      std::string* busy_reason = nullptr);
  /// @brief Stops the threads; the controller stops the arm and releases API control.
  ~JacoArm();
  JacoArm(const JacoArm&) = delete;
  JacoArm& operator=(const JacoArm&) = delete;

  [[nodiscard]] Result<void, JacoError> submit(const ArmCommand& command) {
    return controller_->submit(command);
  }
  void keep_alive() noexcept { controller_->keep_alive(); }
  /// @brief Latches the stop now (wait-free on the arm), then records it in the state directory
  /// with @p reason. @return true if the arm was moving when asked (commanded or measured).
  bool estop(std::string_view reason = "emergency stop");
  /// @brief Writes a latch that only the guard has recorded (a signal's stop) to the state
  /// directory: the guard never does file I/O; the holder's thread (its wait loop) or the
  /// destructor does. @pre none.
  void persist_latch();
  /// @brief A person's reset: clears the latch in the controller and in the state directory.
  [[nodiscard]] Result<void, JacoError> reset_estop();
  /// @brief Why the arm is latched (empty if it is not). @pre none.
  [[nodiscard]] std::string latch_reason() const;
  /// @brief What the hand holds, for the monitor. @pre finite values.
  void set_held(const HeldCapsule& held) { controller_->set_held(held); }
  [[nodiscard]] ArmSnapshot snapshot() const { return controller_->snapshot(); }
  [[nodiscard]] const ArmIdentity& identity() const noexcept { return controller_->identity(); }
  [[nodiscard]] std::int64_t now_ns() const noexcept { return controller_->now_ns(); }
  [[nodiscard]] const UsbTransport& transport() const noexcept { return *transport_; }
  /// @brief True if the guard thread runs with SCHED_FIFO (else it runs, at normal priority).
  [[nodiscard]] bool realtime_guard() const noexcept { return realtime_.load(); }
  /// @brief True if @p s shows motion (a command streaming, or joints measured moving). @pre none.
  [[nodiscard]] static bool moving(const ArmSnapshot& s) noexcept;

 private:
  JacoArm() = default;
  void run() noexcept;
  void run_guard() noexcept;
  void run_notifier() noexcept;
  void pace(std::int64_t& next, std::int64_t clock_start,
            std::chrono::steady_clock::time_point& wall_start) noexcept;

  ArmOptions options_{};
  std::unique_ptr<UsbTransport> transport_;
  std::unique_ptr<JacoController> controller_;
  std::optional<ArmStateDir> state_dir_;
  ArmHold hold_;
  mutable std::mutex latch_mutex_;
  std::string latch_reason_;
  bool latch_was_moving_ = false;
  bool latch_persisted_ = true;
  void latch_in_memory(std::string_view reason, bool was_moving);
  std::atomic<bool> stop_{false};
  std::atomic<bool> realtime_{false};
  std::atomic<std::uint64_t> cycles_{0};
  std::thread thread_, guard_, notifier_;
};

}  // namespace orthoflow::drivers::jaco
