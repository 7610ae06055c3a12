// JacoArm: the controller's USB, guard and notifier threads, holding and latching
// (jaco_arm.hpp).
#include "drivers/jaco/jaco_arm.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>

namespace orthoflow::drivers::jaco {
namespace {

std::atomic<int> g_signal_stop{0};
std::atomic<std::uint32_t> g_signal_count{0};  // every request, so each one latches anew

void on_stop_signal(int signal_number) { request_signal_stop(signal_number); }

const char* signal_name(int signal_number) noexcept {
  switch (signal_number) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    case SIGQUIT:
      return "SIGQUIT";
    default:
      return "a signal";
  }
}

// SCHED_FIFO at a modest priority: above every normal thread, below the kernel's own. Needs
// CAP_SYS_NICE or an rtprio limit (docs/SAFETY.md); without it the guard runs at normal priority.
bool make_realtime(std::thread& thread) noexcept {
  sched_param param{};
  param.sched_priority = 20;
  return pthread_setschedparam(thread.native_handle(), SCHED_FIFO, &param) == 0;
}

}  // namespace

void request_signal_stop(int signal_number) noexcept {
  g_signal_stop.store(signal_number == 0 ? -1 : signal_number, std::memory_order_release);
  g_signal_count.fetch_add(1, std::memory_order_acq_rel);
}

int signal_stop_requested() noexcept { return g_signal_stop.load(std::memory_order_acquire); }

void install_stop_signals() noexcept {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  for (const int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaction(s, &action, nullptr);
}

bool JacoArm::moving(const ArmSnapshot& s) noexcept {
  const auto nonzero = [](double v) { return std::abs(v) > 0.5; };
  return std::any_of(s.commanded.begin(), s.commanded.end(), nonzero) ||
         std::any_of(s.velocity.begin(), s.velocity.end(), nonzero) ||
         s.control == ControlState::MOVING || s.control == ControlState::VELOCITY ||
         s.control == ControlState::HOMING || s.fingers_moving;
}

Result<std::unique_ptr<JacoArm>, JacoError> JacoArm::start(std::unique_ptr<UsbTransport> transport,
                                                           const UsbDeviceInfo& device,
                                                           ArmOptions options,
                                                           std::string* busy_reason) {
  std::unique_ptr<JacoArm> arm(new JacoArm());
  arm->options_ = std::move(options);
  arm->transport_ = std::move(transport);
  const auto busy = [&](std::string why) {
    if (busy_reason != nullptr) *busy_reason = std::move(why);
    JacoError e;
    e.code = JacoError::Code::BUSY;
    return err(e);
  };
  if (!arm->options_.state_dir.empty()) {
    auto dir = ArmStateDir::open(arm->options_.state_dir);
    if (!dir) return busy(dir.error());
    auto hold = dir.value().hold(arm->options_.holder);
    if (!hold) return busy(hold.error());
    arm->hold_ = std::move(hold).value();
    arm->state_dir_.emplace(std::move(dir).value());
  }
  auto controller = JacoController::open(*arm->transport_, device, arm->options_.controller);
  if (!controller) return err(controller.error());
  arm->controller_ = std::move(controller).value();
  if (arm->state_dir_) {
    if (auto latch = arm->state_dir_->latched()) {  // latched by an earlier process: stay still
      arm->latch_reason_ = latch->reason;
      arm->latch_was_moving_ = latch->was_moving;
      arm->controller_->estop();
    }
  }
  arm->thread_ = std::thread([raw = arm.get()] { raw->run(); });
  arm->guard_ = std::thread([raw = arm.get()] { raw->run_guard(); });
  arm->realtime_.store(make_realtime(arm->guard_));
  arm->notifier_ = std::thread([raw = arm.get()] { raw->run_notifier(); });
  return arm;
}

JacoArm::~JacoArm() {
  stop_.store(true, std::memory_order_release);
  cycles_.fetch_add(1);
  cycles_.notify_all();
  for (std::thread* t : {&notifier_, &guard_, &thread_})
    if (t->joinable()) t->join();
  persist_latch();
  controller_.reset();  // stops the arm on this thread, now that the USB thread is gone
}

bool JacoArm::estop(std::string_view reason) {
  const bool was_moving = moving(controller_->snapshot());
  controller_->estop();
  latch_in_memory(reason, was_moving);
  persist_latch();
  return was_moving;
}

void JacoArm::latch_in_memory(std::string_view reason, bool was_moving) {
  std::lock_guard lock(latch_mutex_);
  if (!latch_reason_.empty()) return;  // the first reason stands
  latch_reason_ = std::string(reason);
  latch_was_moving_ = was_moving;
  latch_persisted_ = false;
}

void JacoArm::persist_latch() {
  std::string reason;
  bool was_moving = false;
  {
    // Copied under the lock, written outside it: the guard's latch_in_memory never waits on I/O.
    std::lock_guard lock(latch_mutex_);
    if (latch_persisted_ || latch_reason_.empty()) return;
    reason = latch_reason_;
    was_moving = latch_was_moving_;
    latch_persisted_ = true;
  }
  if (state_dir_) (void)state_dir_->latch(reason, was_moving);
}

Result<void, JacoError> JacoArm::reset_estop() {
  auto reset = controller_->reset_estop();
  if (!reset) return reset;
  std::lock_guard lock(latch_mutex_);
  latch_reason_.clear();
  latch_persisted_ = true;
  if (state_dir_) (void)state_dir_->clear_latch();
  return {};
}

std::string JacoArm::latch_reason() const {
  std::lock_guard lock(latch_mutex_);
  return latch_reason_;
}

void JacoArm::run_guard() noexcept {
  const MonotonicClock& clock = transport_->clock();
  auto next = std::chrono::steady_clock::now();
  std::uint32_t seen = 0;  // a request made before this arm started latches it too
  while (!stop_.load(std::memory_order_acquire)) {
    controller_->guard(clock.now_ns());
    if (const std::uint32_t count = g_signal_count.load(std::memory_order_acquire); count != seen) {
      // Halt now; the file is written by the holder's thread or the destructor (no I/O here).
      seen = count;
      const bool was_moving = moving(controller_->snapshot());
      controller_->estop();
      latch_in_memory(signal_name(signal_stop_requested()), was_moving);
    }
    next += std::chrono::nanoseconds(GUARD_PERIOD_NS);
    std::this_thread::sleep_until(next);
  }
}

void JacoArm::run_notifier() noexcept {
  std::uint64_t seen = cycles_.load();
  while (!stop_.load(std::memory_order_acquire)) {
    cycles_.wait(seen);
    seen = cycles_.load();
    if (stop_.load(std::memory_order_acquire)) break;
    const ArmSnapshot snapshot = controller_->snapshot();
    for (const StateCallback& callback : options_.subscribers) callback(snapshot);
  }
}

void JacoArm::run() noexcept {
  const MonotonicClock& clock = transport_->clock();
  const std::int64_t clock_start = clock.now_ns();
  auto wall_start = std::chrono::steady_clock::now();
  std::int64_t next = clock_start;
  while (!stop_.load(std::memory_order_acquire)) {
    controller_->cycle();
    if (!options_.subscribers.empty()) {
      cycles_.fetch_add(1, std::memory_order_release);
      cycles_.notify_one();
    }
    pace(next, clock_start, wall_start);
  }
}

void JacoArm::pace(std::int64_t& next, std::int64_t clock_start,
                   std::chrono::steady_clock::time_point& wall_start) noexcept {
  const MonotonicClock& clock = transport_->clock();
  next += ARM_PERIOD_NS;
  // Wait for the next period on the transport's clock: a real transport blocks in its event pump,
  // a simulator advances its time. Bounded: a late cycle starts at once (counted by the controller
  // as an overrun), never catches up with a burst.
  const std::int64_t now = clock.now_ns();
  if (next < now) next = now;
  for (int i = 0; i < 4 && clock.now_ns() < next; ++i) {
    const std::int64_t left_ms = (next - clock.now_ns() + 999'999) / 1'000'000;
    (void)transport_->handle_events(UsbTimeout(std::max<std::int64_t>(left_ms, 1)));
  }
  if (!options_.pace_to_wall_clock) return;
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

}  // namespace orthoflow::drivers::jaco
