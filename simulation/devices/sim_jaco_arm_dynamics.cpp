// SimJacoArm's joint dynamics: every mode sets a velocity command for the cycle; the joints
// follow it at the arm's acceleration and deceleration, land exactly on a position goal, and motion
// packets act after the command latency (SimJacoDynamics, sim_jaco_config.hpp).
#include <algorithm>
#include <cmath>

#include "simulation/devices/sim_jaco_arm.hpp"

namespace orthoflow::simulation {

namespace jaco = drivers::jaco;

namespace {
constexpr double DT_S = static_cast<double>(jaco::ARM_PERIOD_NS) * 1e-9;
}  // namespace

bool SimJacoArm::silent(std::int64_t t_ns) const noexcept {
  const SimJacoFaults& f = config_.faults;
  return f.silent_from_ns && t_ns >= *f.silent_from_ns && t_ns < f.silent_until_ns;
}

void SimJacoArm::run_delayed(std::int64_t t_ns) noexcept {
  while (delayed_count_ > 0 && delayed_[delayed_head_].due_ns <= t_ns) {
    const jaco::Packet packet = delayed_[delayed_head_].packet;
    delayed_head_ = (delayed_head_ + 1) % delayed_.size();
    --delayed_count_;
    const auto command = static_cast<jaco::Command>(jaco::read_header(packet).command_id);
    if (command == jaco::Command::ERASE_TRAJECTORIES) {
      erase();
    } else {
      motion_command(command, packet);
    }
  }
}

bool SimJacoArm::move_toward(const jaco::JointAngles& target) noexcept {
  // The fastest approach that can still stop on the target at the arm's deceleration; integrate()
  // then lands on it exactly.
  const double decel = config_.dynamics.decel_deg_s2;
  bool reached = true;
  for (std::size_t j = 0; j < jaco::JOINTS; ++j) {
    const double error = target[j] - joints_[j];
    if (error != 0.0 || velocity_[j] != 0.0) reached = false;
    const double stoppable = std::sqrt(2.0 * decel * std::abs(error));
    desired_[j] = std::copysign(std::min(config_.max_joint_speed_deg_s[j], stoppable), error);
  }
  toward_ = target;
  return reached;
}

void SimJacoArm::move_velocity(const std::array<double, jaco::JOINTS>& deg_s) noexcept {
  for (std::size_t j = 0; j < jaco::JOINTS; ++j) {
    const double top = config_.max_joint_speed_deg_s[j];
    desired_[j] = std::clamp(deg_s[j], -top, top);
  }
}

void SimJacoArm::integrate() noexcept {
  const SimJacoDynamics& d = config_.dynamics;
  for (std::size_t j = 0; j < jaco::JOINTS; ++j) {
    const double v = velocity_[j];
    const bool speeding_up = desired_[j] * v >= 0.0 && std::abs(desired_[j]) > std::abs(v);
    const double step = (speeding_up ? d.accel_deg_s2 : d.decel_deg_s2) * DT_S;
    const double next = v + std::clamp(desired_[j] - v, -step, step);
    double q = joints_[j] + next * DT_S;  // the new speed over the cycle (exact for the ideal arm)
    velocity_[j] = next;
    if (toward_) {
      const double target = (*toward_)[j];
      const bool passed = (target - joints_[j]) * (target - q) <= 0.0;
      if (passed && std::abs(next) <= d.decel_deg_s2 * DT_S + 1e-9) {
        q = target;  // within one braking step of the goal: it lands there
        velocity_[j] = 0.0;
      }
    }
    if (q < limits_.lower[j] || q > limits_.upper[j]) velocity_[j] = 0.0;  // the mechanical stop
    joints_[j] = std::clamp(q, limits_.lower[j], limits_.upper[j]);
  }
}

}  // namespace orthoflow::simulation
