// SimJacoArm: the replies to GET_* requests (JACO.md 5, 6), built with
// drivers/jaco/jaco_protocol.hpp.
#include "simulation/devices/sim_jaco_arm.hpp"

#include <algorithm>

namespace orthoflow::simulation {

namespace jaco = drivers::jaco;

namespace {

jaco::NineFloats nine(const std::array<double, jaco::JOINTS>& values,
                      const std::array<double, jaco::FINGERS>& fingers) noexcept {
  jaco::NineFloats out;
  for (std::size_t i = 0; i < jaco::JOINTS; ++i) out.values[i] = static_cast<float>(values[i]);
  for (std::size_t i = 0; i < jaco::FINGERS; ++i) out.fingers[i] = static_cast<float>(fingers[i]);
  return out;
}

jaco::NineFloats nine(const jaco::CartesianPose& pose,
                      const std::array<double, jaco::FINGERS>& fingers) noexcept {
  const std::array<double, jaco::JOINTS> values = {pose.position.x(), pose.position.y(),
                                                   pose.position.z(), pose.theta.x(),
                                                   pose.theta.y(),    pose.theta.z()};
  return nine(values, fingers);
}

jaco::ClientInfo client_info(const SimJacoConfig& c) noexcept {
  jaco::ClientInfo info;
  info.client_id.assign(c.client_id);
  info.name.assign(c.client_name);
  info.organisation.assign(c.organisation);
  info.serial.assign(c.serial);
  info.model.assign(c.model_string);
  return info;
}

}  // namespace

jaco::CartesianPose SimJacoArm::pose_of(const jaco::JointAngles& joints) const noexcept {
  return jaco::to_pose(jaco::forward_kinematics(joints, *geometry_));
}

jaco::JointAngles SimJacoArm::commanded_joints() const noexcept {
  if (transition_ && joystick_.buttons[jaco::HOME_BUTTON] != 0) return transition_target_;
  if (head_ == Head::POSITION) return head_target_;
  const jaco::TrajectoryPoint& next = fifo_[fifo_head_];
  if (head_ == Head::NONE && fifo_size_ > 0 && next.type == jaco::PositionType::ANGULAR_POSITION) {
    jaco::JointAngles target{};  // queued, starting at the next cycle
    for (std::size_t j = 0; j < jaco::JOINTS; ++j) target[j] = next.target[j];
    return target;
  }
  return joints_;
}

std::optional<jaco::CartesianPose> SimJacoArm::commanded_pose() const noexcept {
  if (head_pose_) return head_pose_;
  const jaco::TrajectoryPoint& next = fifo_[fifo_head_];
  if (head_ == Head::NONE && fifo_size_ > 0 &&
      next.type == jaco::PositionType::CARTESIAN_POSITION) {
    jaco::CartesianPose pose;  // queued, solved at the next cycle
    pose.position = Eigen::Vector3d(next.target[0], next.target[1], next.target[2]);
    pose.theta = Eigen::Vector3d(next.target[3], next.target[4], next.target[5]);
    return pose;
  }
  return std::nullopt;
}

std::optional<jaco::Packet> SimJacoArm::state_reply(jaco::Command command,
                                                    jaco::PacketHeader header) const noexcept {
  using C = jaco::Command;
  std::optional<jaco::Packet> reply;
  switch (command) {
    case C::GET_CLIENT_INFO:
    case C::GET_ARM_INFO:
      return slice_reply(command, header);
    case C::GET_ANG_POS:
    case C::GET_ANG_INFO:
      reply = jaco::encode_nine(command, nine(joints_, fingers_));
      break;
    case C::GET_ANG_COMMAND:
      reply = jaco::encode_nine(command, nine(commanded_joints(), finger_target_));
      break;
    case C::GET_CART_INFO:
      reply = jaco::encode_nine(command, nine(pose_, fingers_));
      break;
    case C::GET_CART_COMMAND: {
      const jaco::CartesianPose target = commanded_pose().value_or(pose_of(commanded_joints()));
      reply = jaco::encode_nine(command, nine(target, finger_target_));
      break;
    }
    case C::GET_ANG_VEL:  // DSP < 5 answers positions here (JACO.md 5)
      reply = config_.dsp.dsp5() ? jaco::encode_nine(command, nine(velocity_, finger_velocity_))
                                 : jaco::encode_nine(command, nine(joints_, fingers_));
      break;
    case C::GET_CART_FORCE:
      reply = jaco::encode_nine(command, config_.cart_force);
      break;
    case C::GET_ANG_FORCE:
      reply = jaco::encode_nine(command, config_.ang_force);
      break;
    case C::GET_ANG_CURRENT:
      reply = jaco::encode_nine(command, config_.ang_current);
      break;
    case C::GET_ANG_CURRENT_MOTOR:
      reply = jaco::encode_nine(command, config_.motor_current);
      break;
    case C::GET_SENSOR_INFO:
      reply = jaco::encode_sensor_info(config_.sensors);
      break;
    case C::GET_FIRMWARE: {
      jaco::Firmware firmware;
      firmware.dsp = config_.dsp;
      firmware.actuators.fill(config_.actuators);
      firmware.fingers.fill(config_.fingers_fw);
      reply = jaco::encode_firmware(firmware);
      break;
    }
    case C::GET_ARM_STATUS: {
      if (!config_.dsp.dsp5()) return std::nullopt;  // DSP < 5 has no command 62 [I]
      jaco::ArmStatus status;
      status.state = state_;
      const std::uint8_t initialised = state_ == jaco::ArmState::NOINIT ? 0 : 1;
      status.finger_init.fill(initialised);
      status.api_control = api_control_ ? 1 : 0;
      status.force_control = force_control_ ? 1 : 0;
      status.current_limitation = 0;
      status.torque_sensors = config_.model == jaco::Model::JACO2 ? 1 : 0;
      reply = jaco::encode_arm_status(status);
      break;
    }
    default:
      return std::nullopt;
  }
  // Every reply echoes the request's slice index [I: JACO.md 4 leaves the reply header open].
  (*reply)[0] = static_cast<std::byte>(header.id_packet & 0xFFU);
  (*reply)[1] = static_cast<std::byte>(header.id_packet >> 8U);
  return reply;
}

jaco::Packet SimJacoArm::slice_reply(jaco::Command command,
                                     jaco::PacketHeader header) const noexcept {
  const bool client = command == jaco::Command::GET_CLIENT_INFO;
  const std::size_t slices = client ? jaco::CLIENT_INFO_SLICES : jaco::ARM_INFO_SLICES;
  const std::uint16_t slice = header.id_packet;
  jaco::Packet reply = jaco::make_packet(
      {slice, 1, header.command_id, static_cast<std::uint16_t>(jaco::BODY_BYTES)});
  if (slice < 1 || slice > slices) return reply;  // a zero body [I]
  const auto body = std::span(reply).subspan(jaco::HEADER_BYTES);
  if (client && slice <= 2) {
    std::array<std::byte, 2 * jaco::BODY_BYTES> strings{};
    jaco::encode_client_info(client_info(config_), strings);
    const auto from = strings.begin() + static_cast<std::ptrdiff_t>((slice - 1) * jaco::BODY_BYTES);
    std::copy(from, from + static_cast<std::ptrdiff_t>(jaco::BODY_BYTES), body.begin());
    return reply;
  }
  std::fill(body.begin(), body.end(), static_cast<std::byte>(slice & 0xFFU));  // filler [I]
  if (!client && slice == 2) {
    jaco::set_body_i32(reply, jaco::ARM_INFO_STATE_OFFSET, static_cast<std::int32_t>(state_));
  }
  return reply;
}

}  // namespace orthoflow::simulation
