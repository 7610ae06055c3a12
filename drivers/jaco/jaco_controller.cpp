#include "drivers/jaco/jaco_controller.hpp"

#include <cmath>

namespace orthoflow::drivers::jaco {
namespace {

Unexpected<JacoError> error_of(JacoError::Code code) {
  JacoError e;
  e.code = code;
  return err(e);
}

Unexpected<JacoError> refused(const SafetyViolation& violation) {
  JacoError e;
  e.code = JacoError::Code::REFUSED;
  e.violation = violation;
  return err(e);
}

}  // namespace

const char* to_string(ControlState state) noexcept {
  switch (state) {
    case ControlState::IDLE:
      return "idle";
    case ControlState::MOVING:
      return "moving";
    case ControlState::VELOCITY:
      return "velocity";
    case ControlState::HOMING:
      return "homing";
    case ControlState::ESTOP:
      return "estop";
    case ControlState::FAULT:
      return "fault";
  }
  return "unknown";
}

const char* to_string(StopReason reason) noexcept {
  switch (reason) {
    case StopReason::NONE:
      return "none";
    case StopReason::REACHED:
      return "reached";
    case StopReason::STOPPED:
      return "stopped";
    case StopReason::WATCHDOG:
      return "watchdog";
    case StopReason::ESTOP:
      return "estop";
    case StopReason::FAULT:
      return "fault";
    case StopReason::SETTLE_TIMEOUT:
      return "settle_timeout";
    case StopReason::HOME_TIMEOUT:
      return "home_timeout";
    case StopReason::REFUSED:
      return "refused";
    case StopReason::SAFETY:
      return "safety";
  }
  return "unknown";
}

JacoController::JacoController(UsbTransport& transport, ControllerOptions options) noexcept
    : transport_(&transport), clock_(&transport.clock()), options_(options) {}

Result<std::unique_ptr<JacoController>, JacoError> JacoController::open(UsbTransport& transport,
                                                                        const UsbDeviceInfo& device,
                                                                        ControllerOptions options) {
  std::unique_ptr<JacoController> controller(new JacoController(transport, options));
  auto started = controller->start_up(device);
  if (!started) return err(started.error());
  return controller;
}

Result<void, JacoError> JacoController::start_up(const UsbDeviceInfo& device) {
  linked_.store(false, std::memory_order_release);  // the guard waits until the link is up
  link_.reset();
  auto link = JacoLink::open(*transport_, device, options_.link);
  if (!link) return err(link.error());
  link_.emplace(std::move(link).value());
  auto identity = link_->read_identity();
  if (!identity) return err(identity.error());
  identity_ = identity.value();
  options_.limits.geometry =
      identity_.model == Model::JACO_V1 ? &jaco_v1_geometry() : &jaco2_geometry();
  options_.limits.max_finger =
      std::min(options_.limits.max_finger, static_cast<double>(finger_closed(identity_.model)));
  // Take control, then make sure nothing latched or queued by an earlier session moves the arm.
  for (Command c : {Command::START_API_CONTROL, Command::SET_CONTROL_ANGULAR}) {
    auto ok = link_->command(c);
    if (!ok) return err(ok.error());
  }
  if (!send_joystick(JoystickState{})) return err(state_.fault_error);
  auto erased = link_->command(Command::ERASE_TRAJECTORIES);
  if (!erased) return err(erased.error());
  auto arm_state = link_->read_state(identity_.firmware.dsp.dsp5());
  if (!arm_state) return err(arm_state.error());
  state_ = ArmSnapshot{};
  state_.arm_state = arm_state.value();
  have_previous_ = false;
  readings_ = {};
  read_state();
  if (state_.fault) return err(state_.fault_error);
  state_.control = ControlState::IDLE;
  last_reply_ns_.store(clock_->now_ns(), std::memory_order_release);
  silent_.store(false, std::memory_order_release);
  linked_.store(true, std::memory_order_release);
  std::lock_guard lock(mutex_);
  pending_motion_.reset();
  pending_fingers_.reset();
  pending_stop_ = false;
  published_ = state_;
  return {};
}

JacoController::~JacoController() {
  if (!link_ || state_.fault) return;
  // Best effort on the way out: stop, then hand control back to the joystick.
  (void)send_joystick(JoystickState{});
  (void)link_->command(Command::ERASE_TRAJECTORIES);
  (void)link_->command(Command::STOP_API_CONTROL);
}

Result<void, JacoError> JacoController::validate(const ArmCommand& command, const ArmSnapshot& now,
                                                 FirmwareProof* proof) const {
  using Kind = ArmCommand::Kind;
  const SafetyLimits& limits = options_.limits;
  if (command.kind == Kind::STOP || command.kind == Kind::KEEP_ALIVE) return {};
  if (now.estop || estop_.load(std::memory_order_acquire)) return error_of(JacoError::Code::ESTOP);
  if (now.fault) return error_of(JacoError::Code::FAULT);
  if (!std::isfinite(command.speed_fraction) || command.speed_fraction <= 0.0 ||
      command.speed_fraction > 1.0) {
    SafetyViolation v;
    v.limit = SafetyViolation::Limit::SPEED;
    v.value = command.speed_fraction;
    v.bound = 1.0;
    return refused(v);
  }
  const bool homed = now.arm_state != ArmState::NOINIT && now.arm_state != ArmState::ERROR;
  switch (command.kind) {
    case Kind::MOVE_JOINTS: {
      if (!homed) return error_of(JacoError::Code::INVALID_STATE);
      auto ok = check_joint_move(limits, now.joints, command.joints, 0.0, now.held);
      if (!ok) return refused(ok.error());
      return {};
    }
    case Kind::MOVE_POSE: {
      if (!homed) return error_of(JacoError::Code::INVALID_STATE);
      auto ok = check_pose(limits, command.pose);
      if (!ok) return refused(ok.error());
      return {};  // submit() solves the IK and checks the joint path
    }
    case Kind::VELOCITY: {
      if (!homed) return error_of(JacoError::Code::INVALID_STATE);
      // An early refusal of what the first period would do, by the monitor's own rules (finite,
      // the speed cap, speeding up held to the acceleration cap, slowing down always allowed);
      // the monitor checks every cycle of the stream as it runs.
      CycleIntent intent;
      intent.joints = now.joints;
      intent.velocity = now.velocity;
      intent.command = command.velocity;
      intent.previous = now.commanded;
      intent.held = now.held;
      auto envelope = check_cycle(limits, intent);
      if (!envelope) return refused(envelope.error());
      return {};
    }
    case Kind::MOVE_FINGERS: {
      // A NOINIT arm ignores finger commands: say so instead of waiting for fingers that never
      // move.
      if (!homed) return error_of(JacoError::Code::INVALID_STATE);
      auto ok = check_fingers(limits, command.fingers);
      if (!ok) return refused(ok.error());
      return {};
    }
    case Kind::HOME:
    case Kind::RETRACT: {
      if (command.kind == Kind::RETRACT &&
          next_button_action(now.arm_state, ArmGoal::RETRACT, false) == ButtonAction::REFUSE)
        return error_of(JacoError::Code::INVALID_STATE);
      // The firmware's motion runs to its pose even if the link fails: all of it must be clear.
      double closed = limits.max_finger;
      for (double f : now.fingers) closed = std::min(closed, f);
      const double open = std::clamp(1.0 - closed / limits.max_finger, 0.0, 1.0);
      const JointAngles& goal =
          command.kind == Kind::RETRACT ? options_.retract_joints : options_.home_joints;
      auto ok = prove_firmware_motion(limits, now.joints, goal, open, now.held);
      if (!ok) return refused(ok.error());
      if (proof != nullptr) *proof = *ok;
      return {};
    }
    default:
      return {};
  }
}

Result<ArmCommand, JacoError> JacoController::check_command(const ArmCommand& command,
                                                            FirmwareProof* proof,
                                                            const ArmSnapshot& now) const {
  auto ok = validate(command, now, proof);
  if (!ok) return err(ok.error());
  ArmCommand accepted = command;
  if (command.kind == ArmCommand::Kind::MOVE_POSE) {
    // Solved on the caller's thread, so an unreachable pose is refused to the caller.
    auto solution = inverse_kinematics(to_transform(command.pose), now.joints,
                                       options_.limits.joints, {}, *options_.limits.geometry);
    if (!solution) {
      SafetyViolation v;
      v.limit = SafetyViolation::Limit::UNREACHABLE;
      return refused(v);
    }
    auto path = check_joint_move(options_.limits, now.joints, solution.value(), 0.0, now.held);
    if (!path) return refused(path.error());
    accepted.kind = ArmCommand::Kind::MOVE_JOINTS;
    accepted.joints = solution.value();
  }
  return accepted;
}

Result<void, JacoError> JacoController::submit(const ArmCommand& command) {
  // Check on a copy, without the lock: the path check and the IK take microseconds to a
  // millisecond, and the USB thread must never wait for them.
  ArmSnapshot now;
  {
    std::lock_guard lock(mutex_);
    now = published_;
  }
  FirmwareProof proof;
  auto checked = check_command(command, &proof, now);
  std::lock_guard lock(mutex_);
  if (!checked) {
    ++published_.refused;
    return err(checked.error());
  }
  const ArmCommand& accepted = checked.value();
  // The latch or a fault may have come while the command was checked.
  if (command.kind != ArmCommand::Kind::STOP && command.kind != ArmCommand::Kind::KEEP_ALIVE) {
    if (published_.estop || estop_.load(std::memory_order_acquire)) {
      ++published_.refused;
      return error_of(JacoError::Code::ESTOP);
    }
    if (published_.fault) {
      ++published_.refused;
      return error_of(JacoError::Code::FAULT);
    }
  }
  last_client_ns_.store(clock_->now_ns(), std::memory_order_release);
  if (command.kind == ArmCommand::Kind::HOME || command.kind == ArmCommand::Kind::RETRACT)
    firmware_proof_ = proof;
  switch (command.kind) {
    case ArmCommand::Kind::KEEP_ALIVE:
      break;
    case ArmCommand::Kind::STOP:
      pending_stop_ = true;
      pending_motion_.reset();
      pending_fingers_.reset();
      break;
    case ArmCommand::Kind::MOVE_FINGERS:
      pending_fingers_ = accepted;
      break;
    default:
      pending_motion_ = accepted;
      break;
  }
  return {};
}

void JacoController::keep_alive() noexcept {
  last_client_ns_.store(clock_->now_ns(), std::memory_order_release);
}

Result<void, JacoError> JacoController::reset_estop() {
  std::lock_guard lock(mutex_);
  if (published_.fault) return error_of(JacoError::Code::FAULT);
  if (!published_.estop && !estop_.load(std::memory_order_acquire)) return {};
  // The latch clears on the USB thread's next cycle, after it has erased once more.
  estop_.store(false, std::memory_order_release);
  published_.estop = false;
  return {};
}

Result<void, JacoError> JacoController::reinitialise(const UsbDeviceInfo& device) {
  return start_up(device);
}

ArmSnapshot JacoController::snapshot() const {
  std::lock_guard lock(mutex_);
  return published_;
}

}  // namespace orthoflow::drivers::jaco
