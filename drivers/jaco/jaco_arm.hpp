#pragma once
/// @file
/// @brief JacoArm: a JacoController on its own USB thread, the asynchronous arm of issue 19. The
/// thread owns the transport, runs cycle() every 10 ms of the transport's clock and hands each
/// snapshot to the subscribers (100 Hz state stream); clients on any thread submit commands, feed
/// the watchdog and pull the emergency stop. No caller polls the arm.
///
/// Simulated time: with `pace_to_wall_clock`, the thread keeps a simulator's clock no faster than
/// wall time, so the simulated arm moves as fast as a real one (the CLI's --sim); without it the
/// simulation runs as fast as the CPU allows (tests), and client threads must then read time from
/// the transport's clock.
#include <atomic>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

#include "drivers/jaco/jaco_controller.hpp"

namespace orthoflow::drivers::jaco {

/// @brief Called on the USB thread after every cycle. Must not block or throw.
using StateCallback = std::function<void(const ArmSnapshot&)>;

struct ArmOptions {
  ControllerOptions controller{};
  bool pace_to_wall_clock = false;
  std::vector<StateCallback> subscribers{};  ///< fixed before start
};

class JacoArm {
 public:
  /// @brief Opens the arm @p device on @p transport (on the calling thread), then starts the USB
  /// thread. @return the start-up error; nothing runs then.
  [[nodiscard]] static Result<std::unique_ptr<JacoArm>, JacoError> start(
      std::unique_ptr<UsbTransport> transport, const UsbDeviceInfo& device, ArmOptions options);
  /// @brief Stops the thread; the controller stops the arm and releases API control.
  ~JacoArm();
  JacoArm(const JacoArm&) = delete;
  JacoArm& operator=(const JacoArm&) = delete;

  [[nodiscard]] Result<void, JacoError> submit(const ArmCommand& command) {
    return controller_->submit(command);
  }
  void keep_alive() noexcept { controller_->keep_alive(); }
  void estop() noexcept { controller_->estop(); }
  [[nodiscard]] Result<void, JacoError> reset_estop() { return controller_->reset_estop(); }
  [[nodiscard]] ArmSnapshot snapshot() const { return controller_->snapshot(); }
  [[nodiscard]] const ArmIdentity& identity() const noexcept { return controller_->identity(); }
  [[nodiscard]] std::int64_t now_ns() const noexcept { return controller_->now_ns(); }
  [[nodiscard]] const UsbTransport& transport() const noexcept { return *transport_; }

 private:
  JacoArm() = default;
  void run() noexcept;

  ArmOptions options_{};
  std::unique_ptr<UsbTransport> transport_;
  std::unique_ptr<JacoController> controller_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace orthoflow::drivers::jaco
