// JacoController's stops: what leaves on the wire (every packet passes halted() or is a stop), the
// safety monitor's gate, the guard, faults and the emergency stop (jaco_controller.hpp).
#include <algorithm>
#include <cmath>

#include "drivers/jaco/jaco_controller.hpp"

namespace orthoflow::drivers::jaco {

bool JacoController::halted() const noexcept {
  return estop_.load(std::memory_order_acquire) || silent_.load(std::memory_order_acquire);
}

bool JacoController::send_joystick(const JoystickState& state) noexcept {
  // A latched stop lets only the release through (a press would start the firmware's motion).
  if (!state.is_release() && halted()) return false;
  Packet reply{};
  auto ok = link_->exchange(encode_joystick(state), reply);
  if (!ok) {
    fail(ok.error());
    return false;
  }
  joystick_dirty_ = !state.is_release();
  return true;
}

bool JacoController::send_velocity(const JointVelocity& joints,
                                   const std::array<double, FINGERS>& fingers) noexcept {
  if (halted()) return false;  // a stop came while this cycle was deciding: nothing moves
  TrajectoryPoint point;
  point.type = PositionType::ANGULAR_VELOCITY;
  point.hand_mode = HandMode::VELOCITY;
  for (std::size_t j = 0; j < JOINTS; ++j) point.target[j] = static_cast<float>(joints[j]);
  for (std::size_t f = 0; f < FINGERS; ++f) point.fingers[f] = static_cast<float>(fingers[f]);
  Packet reply{};
  auto ok = link_->exchange(encode_trajectory(point), reply);
  if (!ok) {
    fail(ok.error());
    return false;
  }
  ++state_.points_sent;
  state_.commanded = joints;
  last_velocity_ = joints;
  return true;
}

void JacoController::fail(const JacoError& error) noexcept {
  if (state_.fault) return;
  state_.fault = true;
  state_.fault_error = error;
  state_.control = ControlState::FAULT;
  state_.last_stop = StopReason::FAULT;
  // Best effort: an arm that is still there (a bad reply, a stall) gets erase and release; an
  // unplugged one cannot hear it.
  const bool gone =
      error.code == JacoError::Code::USB && error.usb.code == UsbError::Code::NO_DEVICE;
  if (!gone && link_) {
    Packet reply{};
    (void)link_->exchange(make_plain_command(Command::ERASE_TRAJECTORIES), reply);
    (void)link_->exchange(encode_joystick(JoystickState{}), reply);
  }
  last_velocity_ = {};
  state_.commanded = {};
  finger_goal_.reset();
  state_.fingers_moving = false;
}

void JacoController::stop_arm(StopReason reason) noexcept {
  if (state_.fault) return;
  if (joystick_dirty_ || button_pressed_) {
    if (!send_joystick(JoystickState{})) return;
  }
  button_pressed_ = false;
  Packet reply{};
  auto erased = link_->exchange(make_plain_command(Command::ERASE_TRAJECTORIES), reply);
  if (!erased) {
    fail(erased.error());
    return;
  }
  if (state_.stop_request_ns != 0 && state_.stop_sent_ns == 0)
    state_.stop_sent_ns = clock_->now_ns();
  last_velocity_ = {};
  state_.commanded = {};
  finger_goal_.reset();
  state_.fingers_moving = false;
  if (state_.control != ControlState::ESTOP) state_.control = ControlState::IDLE;
  state_.last_stop = reason;
}

void JacoController::latch_estop() noexcept {
  if (!state_.estop) {
    state_.stop_request_ns = estop_request_ns_.load(std::memory_order_acquire);
    state_.stop_sent_ns = 0;
  }
  state_.estop = true;
  state_.control = ControlState::ESTOP;
  {
    std::lock_guard lock(mutex_);
    pending_motion_.reset();
    pending_fingers_.reset();
    pending_stop_ = false;
  }
  stop_arm(StopReason::ESTOP);  // every cycle while latched: erase whatever reached the FIFO
}

bool JacoController::monitor_allows(const JointVelocity& v, bool firmware) noexcept {
  const SafetyLimits& limits = options_.limits;
  CycleIntent intent;
  intent.joints = state_.joints;
  intent.velocity = state_.velocity;
  intent.span_velocity = state_.span_velocity;
  intent.span_measured = true;
  intent.command = v;
  intent.previous = last_velocity_;
  intent.firmware = firmware;
  intent.firmware_goal =
      active_.kind == ArmCommand::Kind::RETRACT ? options_.retract_joints : options_.home_joints;
  // Finger units: 0 open, max_finger closed. The widest opening this period is the smaller of
  // where the fingers are and where they are going.
  double finger = *std::min_element(state_.fingers.begin(), state_.fingers.end());
  if (finger_goal_)
    finger = std::min(finger, *std::min_element(finger_goal_->begin(), finger_goal_->end()));
  intent.finger_open = std::clamp(1.0 - finger / limits.max_finger, 0.0, 1.0);
  intent.held = state_.held;
  FirmwareProof proof;
  if (firmware) {
    std::lock_guard lock(mutex_);
    proof = firmware_proof_;
  }
  MonitorCost cost;
  auto verdict = check_cycle(limits, intent, &cost, firmware ? &proof : nullptr);
  state_.monitor_nodes = cost.nodes;
  if (verdict) return true;
  state_.violation = verdict.error();
  ++state_.monitor_stops;
  stop_arm(StopReason::SAFETY);
  return false;
}

void JacoController::guard(std::int64_t now_ns) noexcept {
  if (!linked_.load(std::memory_order_acquire) || silent_.load(std::memory_order_acquire)) return;
  const std::int64_t last = last_reply_ns_.load(std::memory_order_acquire);
  if (now_ns - last <= options_.silence_fault_ns) return;
  silent_.store(true, std::memory_order_release);
  // Say so now, whatever the USB thread is waiting for; that thread sends the best-effort stop
  // when its transfer returns.
  std::lock_guard lock(mutex_);
  if (published_.fault) return;
  published_.fault = true;
  published_.control = ControlState::FAULT;
  published_.last_stop = StopReason::FAULT;
  published_.commanded = {};
  published_.fault_error.code = JacoError::Code::USB;
  published_.fault_error.usb = UsbError{UsbError::Code::TIMEOUT, 0, "silent arm"};
}

void JacoController::set_held(const HeldCapsule& held) {
  std::lock_guard lock(mutex_);
  held_ = held;
}

void JacoController::publish() noexcept {
  std::lock_guard lock(mutex_);
  const std::uint64_t refused = published_.refused;
  const bool guarded_fault = published_.fault && !state_.fault;
  published_ = state_;
  published_.refused += refused;
  state_.refused = 0;
  state_.held = held_;
  if (state_.estop || estop_.load(std::memory_order_acquire)) published_.estop = true;
  if (guarded_fault || silent_.load(std::memory_order_acquire)) {
    published_.fault = true;
    published_.control = ControlState::FAULT;
  }
}

}  // namespace orthoflow::drivers::jaco
