// JacoController's USB-thread half: the 10 ms cycle, the watchdog, the streamed moves and the
// virtual button, each through the safety monitor's gate (jaco_controller.hpp; stops and faults in
// jaco_controller_stop.cpp).
#include <algorithm>
#include <cmath>

#include "drivers/jaco/jaco_controller.hpp"

namespace orthoflow::drivers::jaco {
namespace {

constexpr double PERIOD_S = static_cast<double>(ARM_PERIOD_NS) * 1e-9;
constexpr double STILL_DEG_S = 0.5;  // measured speed below which a joint counts as still

}  // namespace

void JacoController::read_state() noexcept {
  auto joints = link_->read_nine(Command::GET_ANG_POS);
  if (!joints) {
    fail(joints.error());
    return;
  }
  const std::int64_t now = clock_->now_ns();
  last_reply_ns_.store(now, std::memory_order_release);
  state_.last_reply_ns = now;
  JointAngles q{};
  for (std::size_t j = 0; j < JOINTS; ++j) q[j] = joints.value().values[j];
  // The arm updates its positions every 10 ms: a difference over a span of one or two periods may
  // hold one step more or less than its time. The velocity is taken over the newest earlier
  // reading at least two periods old, so such a miscount is at most a third.
  const Reading* base = nullptr;
  for (std::size_t i = 0; i < readings_.size(); ++i) {
    const Reading& r = readings_[(reading_next_ + readings_.size() - 1 - i) % readings_.size()];
    if (!have_previous_ || r.t_ns == 0) break;
    base = &r;
    if (now - r.t_ns >= 2 * ARM_PERIOD_NS) break;
  }
  if (base != nullptr && now > base->t_ns) {
    const double dt = static_cast<double>(now - base->t_ns) * 1e-9;
    for (std::size_t j = 0; j < JOINTS; ++j) state_.velocity[j] = (q[j] - base->q[j]) / dt;
  }
  // The oldest reading kept, when it is at least 50 ms old: the span the firmware's speed is judged
  // over (a loaded host's late reply does not make a step look like two).
  const Reading& oldest = readings_[reading_next_];
  if (have_previous_ && oldest.t_ns != 0 && now - oldest.t_ns >= 5 * ARM_PERIOD_NS) {
    const double dt = static_cast<double>(now - oldest.t_ns) * 1e-9;
    for (std::size_t j = 0; j < JOINTS; ++j) state_.span_velocity[j] = (q[j] - oldest.q[j]) / dt;
  } else {
    state_.span_velocity = state_.velocity;
  }
  readings_[reading_next_] = {now, q};
  reading_next_ = (reading_next_ + 1) % readings_.size();
  have_previous_ = true;
  state_.joints = q;
  for (std::size_t f = 0; f < FINGERS; ++f) state_.fingers[f] = joints.value().fingers[f];
  state_.pose = to_pose(forward_kinematics(q, *options_.limits.geometry));
  state_.stamp_ns = now;
  // One slow read per cycle at most, so a cycle stays a few exchanges long.
  const std::uint64_t slot = state_.cycle % 100;
  if (slot % 10 == 3) {
    auto sensors = link_->read_sensors();
    if (!sensors) return fail(sensors.error());
    state_.sensors = sensors.value();
  } else if (slot % 10 == 7) {
    auto currents = link_->read_nine(Command::GET_ANG_CURRENT);
    if (!currents) return fail(currents.error());
    for (std::size_t j = 0; j < JOINTS; ++j) state_.currents[j] = currents.value().values[j];
  } else if (slot == 50 || state_.control == ControlState::HOMING) {
    auto arm_state = link_->read_state(identity_.firmware.dsp.dsp5());
    if (!arm_state) return fail(arm_state.error());
    state_.arm_state = arm_state.value();
  }
}

std::array<double, FINGERS> JacoController::finger_velocity() const noexcept {
  std::array<double, FINGERS> v{};
  if (!finger_goal_) return v;
  const double range = options_.limits.max_finger;
  const double cap = range;  // full range in one second at most
  for (std::size_t f = 0; f < FINGERS; ++f) {
    v[f] = std::clamp(4.0 * ((*finger_goal_)[f] - state_.fingers[f]), -cap, cap);
  }
  return v;
}

bool JacoController::fingers_stalled(std::int64_t now) noexcept {
  double travel = 0.0;
  for (std::size_t f = 0; f < FINGERS; ++f)
    travel = std::max(travel, std::abs(state_.fingers[f] - finger_mark_[f]));
  if (travel > options_.finger_stall_travel * options_.limits.max_finger) {
    finger_mark_ = state_.fingers;
    finger_mark_ns_ = now;
    return false;
  }
  return now - finger_mark_ns_ > options_.finger_stall_ns;
}

void JacoController::start_pending(std::int64_t now) noexcept {
  std::optional<ArmCommand> motion;
  std::optional<ArmCommand> fingers;
  bool stop = false;
  {
    std::lock_guard lock(mutex_);
    motion.swap(pending_motion_);
    fingers.swap(pending_fingers_);
    stop = std::exchange(pending_stop_, false);
  }
  if (stop) stop_arm(StopReason::STOPPED);
  if (fingers) {
    finger_goal_ = fingers->fingers;
    finger_mark_ = state_.fingers;
    finger_mark_ns_ = now;
    state_.fingers_blocked = false;
  }
  if (!motion || state_.fault) return;
  const SafetyLimits& limits = options_.limits;
  // A new command ends the button sequence of an earlier HOME / RETRACT.
  if (button_pressed_ && motion->kind != ArmCommand::Kind::HOME &&
      motion->kind != ArmCommand::Kind::RETRACT) {
    if (!send_joystick(JoystickState{})) return;
    button_pressed_ = false;
  }
  active_ = *motion;
  motion_start_ns_ = now;
  switch (motion->kind) {
    case ArmCommand::Kind::MOVE_JOINTS: {
      // The arm may have moved since the command was checked: check the path from here again.
      if (auto path = check_joint_move(limits, state_.joints, active_.joints, 0.0, state_.held);
          !path) {
        state_.violation = path.error();
        state_.last_stop = StopReason::REFUSED;
        ++state_.refused;
        return;
      }
      const double speed = limits.max_joint_speed_deg_s * motion->speed_fraction;
      profile_ = JointProfile(state_.joints, active_.joints, speed, limits.max_joint_accel_deg_s2);
      state_.control = ControlState::MOVING;
      break;
    }
    case ArmCommand::Kind::VELOCITY:
      state_.control = ControlState::VELOCITY;
      break;
    case ArmCommand::Kind::HOME:
    case ArmCommand::Kind::RETRACT:
      state_.control = ControlState::HOMING;
      break;
    default:
      break;
  }
}

void JacoController::run_motion(std::int64_t now) noexcept {
  const SafetyLimits& limits = options_.limits;
  JointVelocity v{};
  if (state_.control == ControlState::MOVING) {
    const double t = static_cast<double>(now - motion_start_ns_) * 1e-9;
    const double speed = limits.max_joint_speed_deg_s * active_.speed_fraction;
    v = velocity_command(profile_, t + PERIOD_S, state_.joints, last_velocity_, options_.gain_per_s,
                         speed, limits.max_joint_accel_deg_s2, PERIOD_S);
    const bool done = t >= profile_.duration_s() &&
                      max_joint_error(active_.joints, state_.joints) <= options_.goal_tolerance_deg;
    if (done) {
      state_.control = ControlState::IDLE;
      state_.last_stop = StopReason::REACHED;
      v = {};
    } else if (static_cast<double>(now - motion_start_ns_) >
               profile_.duration_s() * 1e9 + static_cast<double>(options_.settle_timeout_ns)) {
      return stop_arm(StopReason::SETTLE_TIMEOUT);
    }
  } else if (state_.control == ControlState::VELOCITY) {
    v = active_.velocity;
  }
  const std::array<double, FINGERS> fv = finger_velocity();
  if (finger_goal_) {
    bool fingers_done = true;
    for (std::size_t f = 0; f < FINGERS; ++f) {
      fingers_done = fingers_done && std::abs((*finger_goal_)[f] - state_.fingers[f]) <=
                                         options_.finger_tolerance * limits.max_finger;
    }
    if (fingers_done) {
      finger_goal_.reset();
    } else if (fingers_stalled(now)) {
      finger_goal_.reset();
      state_.fingers_blocked = true;
    }
  }
  state_.fingers_moving = finger_goal_.has_value();
  const bool moving = std::any_of(v.begin(), v.end(), [](double x) { return x != 0.0; });
  const bool was_moving =
      std::any_of(last_velocity_.begin(), last_velocity_.end(), [](double x) { return x != 0.0; });
  // An arm that is still and told nothing cannot move: only then is the monitor skipped.
  const bool still = std::all_of(state_.velocity.begin(), state_.velocity.end(),
                                 [](double x) { return std::abs(x) < STILL_DEG_S; });
  if (!moving && !was_moving && !finger_goal_ && still) return;
  if (!monitor_allows(v, false)) return;
  if (moving || was_moving || finger_goal_) (void)send_velocity(v, fv);
}

void JacoController::run_homing(std::int64_t now) noexcept {
  const ArmGoal goal = active_.kind == ArmCommand::Kind::RETRACT ? ArmGoal::RETRACT : ArmGoal::HOME;
  if (now - motion_start_ns_ > options_.home_timeout_ns) return stop_arm(StopReason::HOME_TIMEOUT);
  if (!monitor_allows(state_.velocity, true)) return;
  switch (next_button_action(state_.arm_state, goal, button_pressed_)) {
    case ButtonAction::PRESS:
      if (!send_joystick(home_button_press())) return;
      button_pressed_ = true;
      button_sent_ns_ = now;
      button_resent_ = false;
      break;
    case ButtonAction::RELEASE:
      if (!send_joystick(JoystickState{})) return;
      button_pressed_ = false;
      break;
    case ButtonAction::WAIT:
      // DSP >= 5 sometimes ignores one joystick packet: send the press again 100 ms later.
      if (identity_.firmware.dsp.dsp5() && !button_resent_ &&
          now - button_sent_ns_ >= options_.double_send_gap_ns) {
        if (!send_joystick(home_button_press())) return;
        button_resent_ = true;
      }
      break;
    case ButtonAction::DONE:
      stop_arm(StopReason::REACHED);
      break;
    case ButtonAction::REFUSE:
      stop_arm(StopReason::REFUSED);
      break;
  }
}

void JacoController::cycle() noexcept {
  if (!link_) return;
  const std::int64_t start = clock_->now_ns();
  ++state_.cycle;
  if (!state_.fault && silent_.load(std::memory_order_acquire))
    fail(JacoError{JacoError::Code::USB, UsbError{UsbError::Code::TIMEOUT, 0, "silent arm"}});
  if (!state_.fault) read_state();
  const std::int64_t now = clock_->now_ns();
  if (!state_.fault) {
    if (estop_.load(std::memory_order_acquire)) {
      latch_estop();
    } else {
      if (state_.estop) {
        state_.estop = false;
        state_.control = ControlState::IDLE;
      }
      run_modes(now);
    }
  }
  if (clock_->now_ns() - start > ARM_PERIOD_NS) ++state_.cycles_overrun;
  publish();
}

void JacoController::run_modes(std::int64_t now) noexcept {
  start_pending(now);
  const bool active = state_.control == ControlState::MOVING ||
                      state_.control == ControlState::VELOCITY ||
                      state_.control == ControlState::HOMING || finger_goal_.has_value();
  // Watchdog: stop in the last cycle that still lies before the deadline.
  const std::int64_t deadline =
      last_client_ns_.load(std::memory_order_acquire) + options_.command_timeout_ns;
  if (active && now + ARM_PERIOD_NS > deadline) {
    ++state_.watchdog_stops;
    stop_arm(StopReason::WATCHDOG);
  } else if (state_.control == ControlState::HOMING) {
    run_homing(now);
    if (finger_goal_ && !state_.fault && state_.control == ControlState::HOMING) run_motion(now);
  } else if (!state_.fault) {
    run_motion(now);  // idle too: the monitor watches an arm that should be still
  }
}

}  // namespace orthoflow::drivers::jaco
