// SimJacoArm: the commands an OUT packet carries (JACO.md 6, 9, 10): API and control modes, force
// control, erase, the joystick with the HOME / RETRACT button, and trajectory points into the FIFO.
// Anything else is a request answered by sim_jaco_arm_replies.cpp.
#include "simulation/devices/sim_jaco_arm.hpp"

namespace orthoflow::simulation {

namespace jaco = drivers::jaco;

void SimJacoArm::handle(std::span<const std::byte, jaco::PACKET_BYTES> packet,
                        jaco::PacketHeader header, std::optional<jaco::Packet>& reply) noexcept {
  using C = jaco::Command;
  const auto command = static_cast<C>(header.command_id);
  const bool motion = command == C::JOYSTICK || command == C::SEND_BASIC_TRAJECTORY ||
                      command == C::ERASE_TRAJECTORIES;
  if (motion && config_.dynamics.command_latency_ns > 0) {
    // Acked now; it acts once the command latency has passed (SimJacoDynamics).
    if (delayed_count_ == delayed_.size()) {
      ++counters_.delayed_lost;
    } else {
      Delayed& d = delayed_[(delayed_head_ + delayed_count_++) % delayed_.size()];
      d.due_ns = now_ns_ + config_.dynamics.command_latency_ns;
      std::copy(packet.begin(), packet.end(), d.packet.begin());
    }
  } else if (command == C::JOYSTICK || command == C::SEND_BASIC_TRAJECTORY) {
    motion_command(command, packet);
  } else if (!setting_command(command)) {
    reply = state_reply(command, header);
    if (!reply) ++counters_.unknown_commands;
    return;
  }
  reply = jaco::make_packet({header.id_packet, 1, header.command_id, 0});  // the ack
}

bool SimJacoArm::setting_command(jaco::Command command) noexcept {
  using C = jaco::Command;
  switch (command) {
    case C::START_API_CONTROL:
      api_control_ = true;
      return true;
    case C::STOP_API_CONTROL:
      api_control_ = false;  // queued points and a latched joystick keep acting [I]
      return true;
    case C::SET_CONTROL_ANGULAR:
      mode_ = SimJacoControlMode::ANGULAR;
      return true;
    case C::SET_CONTROL_CARTESIAN:
      mode_ = SimJacoControlMode::CARTESIAN;
      pose_ = pose_of(joints_);
      return true;
    case C::START_FORCE_CONTROL:
      force_control_ = config_.model == jaco::Model::JACO2;  // v1: no torque sensors
      return true;
    case C::STOP_FORCE_CONTROL:
      force_control_ = false;
      return true;
    case C::ERASE_TRAJECTORIES:
      erase();
      return true;
    default:
      return false;
  }
}

void SimJacoArm::motion_command(jaco::Command command,
                                std::span<const std::byte, jaco::PACKET_BYTES> packet) noexcept {
  if (command == jaco::Command::JOYSTICK) {
    if (api_control_) {
      joystick_command(packet);
    } else {
      ++counters_.ignored_commands;
    }
    return;
  }
  if (api_control_ && state_ != jaco::ArmState::NOINIT) {
    trajectory_command(packet);
  } else {
    ++counters_.ignored_commands;
  }
}

void SimJacoArm::joystick_command(std::span<const std::byte, jaco::PACKET_BYTES> packet) noexcept {
  const std::optional<std::int64_t> previous = last_joystick_ns_;
  last_joystick_ns_ = now_ns_;
  const SimJacoFaults& f = config_.faults;
  if (f.fw5_ignore_first_joystick && config_.dsp.dsp5() &&
      (!previous || now_ns_ - *previous > f.fw5_quirk_window_ns)) {
    ++counters_.joystick_ignored;
    return;
  }
  jaco::JoystickState state;
  if (jaco::decode_joystick(packet, state) != jaco::PacketCheck::OK) {
    ++counters_.malformed_commands;
    return;
  }
  const bool was_pressed = joystick_.buttons[jaco::HOME_BUTTON] != 0;
  const bool pressed = state.buttons[jaco::HOME_BUTTON] != 0;
  joystick_ = state;
  if (!was_pressed && pressed) press_home_button();
  if (was_pressed && !pressed) {  // a release stops a HOME / RETRACT move where it is
    transition_ = false;
    standby_since_ns_.reset();
  }
}

void SimJacoArm::press_home_button() noexcept {
  using S = jaco::ArmState;
  switch (state_) {
    case S::NOINIT:
      if (config_.faults.never_leave_noinit) return;
      state_ = S::NORMAL_TO_READY;
      break;
    case S::READY_STANDBY:
    case S::RETRACT_TO_READY:  // stopped on its way HOME: a press reverses it (JACO.md 10.1)
      state_ = S::READY_TO_RETRACT;
      break;
    case S::RETRACT_STANDBY:
    case S::READY_TO_RETRACT:  // stopped on its way to RETRACT: a press reverses it
      state_ = S::RETRACT_TO_READY;
      break;
    case S::NORMAL:
    case S::NORMAL_TO_READY:
    case S::ERROR:
    default:
      state_ = S::NORMAL_TO_READY;  // only HOME is reachable from a normal pose
      break;
  }
  transition_ = true;
  transition_target_ = state_ == S::READY_TO_RETRACT ? config_.retract_joints : config_.home_joints;
  standby_since_ns_.reset();
}

void SimJacoArm::trajectory_command(
    std::span<const std::byte, jaco::PACKET_BYTES> packet) noexcept {
  jaco::TrajectoryPoint point;
  if (jaco::decode_trajectory(packet, point) != jaco::PacketCheck::OK) {
    ++counters_.malformed_commands;
    return;
  }
  if (fifo_size_ == fifo_.size()) {
    ++counters_.points_dropped;  // acked all the same (JACO.md 9: a faster stream fills it)
    return;
  }
  fifo_[(fifo_head_ + fifo_size_) % fifo_.size()] = point;
  ++fifo_size_;
  ++counters_.points_queued;
}

void SimJacoArm::erase() noexcept {
  counters_.points_erased += fifo_size_;
  fifo_size_ = 0;
  head_ = Head::NONE;
  head_pose_.reset();
  head_finger_velocity_ = false;
  finger_target_ = fingers_;  // the fingers stop where they are
}

}  // namespace orthoflow::simulation
