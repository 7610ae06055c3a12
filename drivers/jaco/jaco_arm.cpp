#include "drivers/jaco/jaco_arm.hpp"

#include <algorithm>
#include <chrono>

namespace orthoflow::drivers::jaco {

Result<std::unique_ptr<JacoArm>, JacoError> JacoArm::start(std::unique_ptr<UsbTransport> transport,
                                                           const UsbDeviceInfo& device,
                                                           ArmOptions options) {
  std::unique_ptr<JacoArm> arm(new JacoArm());
  arm->options_ = std::move(options);
  arm->transport_ = std::move(transport);
  auto controller = JacoController::open(*arm->transport_, device, arm->options_.controller);
  if (!controller) return err(controller.error());
  arm->controller_ = std::move(controller).value();
  arm->thread_ = std::thread([raw = arm.get()] { raw->run(); });
  return arm;
}

JacoArm::~JacoArm() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  controller_.reset();  // stops the arm on this thread, now that the USB thread is gone
}

void JacoArm::run() noexcept {
  const MonotonicClock& clock = transport_->clock();
  const std::int64_t clock_start = clock.now_ns();
  auto wall_start = std::chrono::steady_clock::now();
  std::int64_t next = clock_start;
  while (!stop_.load(std::memory_order_acquire)) {
    controller_->cycle();
    if (!options_.subscribers.empty()) {  // one copy of the snapshot per cycle, and only if used
      const ArmSnapshot snapshot = controller_->snapshot();
      for (const StateCallback& callback : options_.subscribers) callback(snapshot);
    }
    next += ARM_PERIOD_NS;
    // Wait for the next period on the transport's clock: a real transport blocks in its event
    // pump, a simulator advances its time. Bounded: a late cycle starts at once (counted by the
    // controller as an overrun), never catches up with a burst.
    const std::int64_t now = clock.now_ns();
    if (next < now) next = now;
    for (int i = 0; i < 4 && clock.now_ns() < next; ++i) {
      const std::int64_t left_ms = (next - clock.now_ns() + 999'999) / 1'000'000;
      (void)transport_->handle_events(UsbTimeout(std::max<std::int64_t>(left_ms, 1)));
    }
    if (options_.pace_to_wall_clock) {
      // Keep simulated time no faster than wall time. After a stall (the process was descheduled)
      // move the origin instead of running cycles back to back to catch up.
      const auto due = wall_start + std::chrono::nanoseconds(clock.now_ns() - clock_start);
      const auto wall_now = std::chrono::steady_clock::now();
      if (wall_now - due > std::chrono::nanoseconds(ARM_PERIOD_NS)) {
        wall_start += wall_now - due;
      } else {
        std::this_thread::sleep_until(due);
      }
    }
  }
}

}  // namespace orthoflow::drivers::jaco
