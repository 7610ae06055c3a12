// SimJacoArm: construction, power-on, receiving an OUT packet, the reply queue and its faults. The
// commands: sim_jaco_arm_commands.cpp; replies to GET_* requests: sim_jaco_arm_replies.cpp; the
// 10 ms cycle (the button state machine, axes, the trajectory FIFO): sim_jaco_arm_motion.cpp.
#include "simulation/devices/sim_jaco_arm.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/assert.hpp"

namespace orthoflow::simulation {

namespace jaco = drivers::jaco;

namespace {

bool valid_rate(double rate) noexcept { return rate >= 0.0 && rate <= 1.0; }

void put_u16(jaco::Packet& packet, std::size_t offset, std::uint16_t value) noexcept {
  packet[offset] = static_cast<std::byte>(value & 0xFFU);
  packet[offset + 1] = static_cast<std::byte>(value >> 8U);
}

}  // namespace

SimJacoConfig sim_jaco_v1_config() {
  SimJacoConfig config;
  config.model = jaco::Model::JACO_V1;
  config.model_string = "JACO v1";
  config.serial = "PJ00320019140501";
  config.dsp = {4, 2, 0};
  config.actuators = {4, 2, 0};
  config.fingers_fw = {1, 0, 0};
  config.max_joint_speed_deg_s = {20.0, 20.0, 20.0, 30.0, 30.0, 30.0};
  config.max_linear_speed_m_s = 0.15;
  return config;
}

SimJacoArm::SimJacoArm(SimJacoConfig config, std::int64_t start_ns)
    : config_(std::move(config)),
      rng_(config_.fault_seed),
      limits_(jaco::jaco_joint_limits()),
      geometry_(config_.model == jaco::Model::JACO2 ? &jaco::jaco2_geometry()
                                                    : &jaco::jaco_v1_geometry()) {
  const SimJacoConfig& c = config_;
  for (const std::string* s :
       {&c.model_string, &c.serial, &c.client_name, &c.client_id, &c.organisation}) {
    OF_ENFORCE(s->size() < jaco::CLIENT_STRING_BYTES && s->find('\0') == std::string::npos,
               "SimJacoArm: client-info strings hold at most 19 chars");
  }
  OF_ENFORCE(c.start_state == jaco::ArmState::NOINIT || c.start_state == jaco::ArmState::NORMAL ||
                 c.start_state == jaco::ArmState::READY_STANDBY ||
                 c.start_state == jaco::ArmState::RETRACT_STANDBY,
             "SimJacoArm: start in NOINIT, NORMAL, READY_STANDBY or RETRACT_STANDBY");
  OF_ENFORCE(inside_limits(c.home_joints) && inside_limits(c.retract_joints),
             "SimJacoArm: HOME and RETRACT must lie inside the joint limits");
  OF_ENFORCE(!c.start_joints || inside_limits(*c.start_joints),
             "SimJacoArm: the start pose must lie inside the joint limits");
  for (const double v : c.max_joint_speed_deg_s) {
    OF_ENFORCE(std::isfinite(v) && v > 0.0, "SimJacoArm: joint speeds must be > 0");
  }
  finger_max_ = c.finger_max.value_or(c.model == jaco::Model::JACO2 ? 6800.0 : 60.0);
  finger_speed_ = c.finger_speed.value_or(finger_max_ / 2.0);
  OF_ENFORCE(std::isfinite(finger_max_) && finger_max_ > 0.0 && std::isfinite(finger_speed_) &&
                 finger_speed_ > 0.0,
             "SimJacoArm: finger range and speed must be > 0");
  for (const double f : c.start_fingers) {
    OF_ENFORCE(f >= 0.0 && f <= finger_max_, "SimJacoArm: start fingers outside [0, finger_max]");
  }
  OF_ENFORCE(c.max_linear_speed_m_s > 0.0 && c.max_angular_speed_rad_s > 0.0,
             "SimJacoArm: Cartesian speeds must be > 0");
  const SimJacoFaults& f = c.faults;
  OF_ENFORCE(valid_rate(f.drop_out_rate) && valid_rate(f.in_timeout_rate) &&
                 valid_rate(f.garbage_reply_rate) && valid_rate(f.corrupt_body_rate) &&
                 valid_rate(f.wrong_command_rate),
             "SimJacoArm: fault rates lie in [0, 1]");
  OF_ENFORCE(f.stale_replies <= SIM_JACO_REPLY_QUEUE, "SimJacoArm: too many stale replies");
  OF_ENFORCE(c.dynamics.accel_deg_s2 > 0.0 && c.dynamics.decel_deg_s2 > 0.0 &&
                 c.dynamics.command_latency_ns >= 0,
             "SimJacoArm: dynamics need positive rates and a latency >= 0");
  power_on(start_ns);
}

void SimJacoArm::power_on(std::int64_t now_ns) noexcept {
  const SimJacoConfig& c = config_;
  now_ns_ = now_ns;
  next_cycle_ns_ = now_ns + jaco::ARM_PERIOD_NS;
  state_ = c.start_state;
  api_control_ = false;
  force_control_ = false;
  mode_ = SimJacoControlMode::ANGULAR;
  joints_ = c.start_joints.value_or(
      c.start_state == jaco::ArmState::READY_STANDBY ? c.home_joints : c.retract_joints);
  velocity_ = {};
  desired_ = {};
  toward_.reset();
  delayed_count_ = 0;
  fingers_ = c.start_fingers;
  finger_velocity_ = {};
  finger_target_ = fingers_;
  pose_ = pose_of(joints_);
  last_motion_ns_.reset();
  joystick_ = {};
  last_joystick_ns_.reset();
  transition_ = false;
  standby_since_ns_.reset();
  fifo_head_ = 0;
  fifo_size_ = 0;
  head_ = Head::NONE;
  head_pose_.reset();
  head_finger_velocity_ = false;
  head_ran_ = false;
  reset_replies();
}

void SimJacoArm::power_cycle(std::int64_t now_ns) noexcept { power_on(std::max(now_ns, now_ns_)); }

bool SimJacoArm::fault(double rate) noexcept { return rate > 0.0 && rng_.uniform() < rate; }

void SimJacoArm::receive(std::span<const std::byte, jaco::PACKET_BYTES> packet,
                         std::int64_t now_ns) noexcept {
  step(now_ns);
  ++counters_.packets;
  if (silent(now_ns)) {
    ++counters_.silent_drops;
    return;
  }
  if (fault(config_.faults.drop_out_rate)) {
    ++counters_.dropped_outs;
    return;
  }
  const jaco::PacketHeader header = jaco::read_header(packet);
  std::optional<jaco::Packet> reply;
  handle(packet, header, reply);
  if (!reply) return;
  apply_reply_faults(reply, header.command_id);
  if (reply) queue_reply(*reply);
}

void SimJacoArm::queue_reply(jaco::Packet reply) noexcept {
  if (reply_count_ == replies_.size()) {  // the oldest is lost [I]
    reply_head_ = (reply_head_ + 1) % replies_.size();
    --reply_count_;
    ++counters_.replies_lost;
  }
  replies_[(reply_head_ + reply_count_) % replies_.size()] = reply;
  ++reply_count_;
  ++counters_.replies;
}

jaco::Packet SimJacoArm::take_reply() noexcept {
  OF_ENFORCE(reply_count_ > 0, "SimJacoArm::take_reply: no reply pending");
  const jaco::Packet reply = replies_[reply_head_];
  reply_head_ = (reply_head_ + 1) % replies_.size();
  --reply_count_;
  return reply;
}

void SimJacoArm::reset_replies() noexcept {
  counters_.replies_lost += reply_count_;
  reply_count_ = 0;
  reply_head_ = 0;
  for (std::uint32_t i = 0; i < config_.faults.stale_replies; ++i) {
    jaco::NineFloats stale;
    for (std::size_t j = 0; j < jaco::JOINTS; ++j) stale.values[j] = static_cast<float>(joints_[j]);
    queue_reply(jaco::encode_nine(jaco::Command::GET_ANG_POS, stale));
  }
}

void SimJacoArm::apply_reply_faults(std::optional<jaco::Packet>& reply,
                                    std::uint16_t command) noexcept {
  const SimJacoFaults& f = config_.faults;
  if (fault(f.in_timeout_rate)) {
    ++counters_.suppressed_replies;
    reply.reset();
    return;
  }
  const auto random_bytes = [&](std::size_t from) {
    for (std::size_t i = from; i < jaco::PACKET_BYTES; i += 8) {
      const std::uint64_t bits = rng_.next();
      for (std::size_t b = 0; b < 8 && i + b < jaco::PACKET_BYTES; ++b) {
        (*reply)[i + b] = static_cast<std::byte>((bits >> (8U * b)) & 0xFFU);
      }
    }
  };
  if (fault(f.garbage_reply_rate)) {
    random_bytes(0);
    const std::uint16_t id = jaco::read_header(*reply).command_id;
    if (id == command) put_u16(*reply, 4, static_cast<std::uint16_t>(id ^ 0x8000U));
    ++counters_.garbage_replies;
    return;
  }
  if (fault(f.corrupt_body_rate)) {
    random_bytes(jaco::HEADER_BYTES);
    jaco::set_body_float(*reply, 0, std::nanf(""));
    ++counters_.corrupt_replies;
    return;
  }
  if (fault(f.wrong_command_rate)) {
    put_u16(*reply, 4, static_cast<std::uint16_t>(command + 1U));
    ++counters_.wrong_command_replies;
  }
}

}  // namespace orthoflow::simulation
