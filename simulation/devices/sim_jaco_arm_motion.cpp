// SimJacoArm: the DSP's 10 ms cycle. Button 2 first (the HOME / RETRACT state machine), then the
// latched axes, then the trajectory FIFO; the fingers; the pose of command 104.
#include "simulation/devices/sim_jaco_arm.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::simulation {

namespace jaco = drivers::jaco;

namespace {

constexpr double DT_S = static_cast<double>(jaco::ARM_PERIOD_NS) * 1e-9;
constexpr double MAX_DELAY_S = 3600.0;  // a TIME_DELAY point holds at most this long
// Tighter than the IK's default, so Cartesian steps of about a millimetre do not drift.
constexpr jaco::IkTolerance IK_TOLERANCE{1e-6, 1e-5};

double clamp_axis(float axis) noexcept { return std::clamp(static_cast<double>(axis), -1.0, 1.0); }

Eigen::Vector3d limit_norm(Eigen::Vector3d v, double max_norm) noexcept {
  const double n = v.norm();
  if (n > max_norm) v *= max_norm / n;
  return v;
}

}  // namespace

bool SimJacoArm::inside_limits(const jaco::JointAngles& angles) const noexcept {
  // Written out rather than JointLimits::contains, so the simulator checks its own bounds.
  for (std::size_t j = 0; j < jaco::JOINTS; ++j) {
    if (!(angles[j] >= limits_.lower[j] && angles[j] <= limits_.upper[j])) return false;  // NaN too
  }
  return true;
}

bool SimJacoArm::moving() const noexcept {
  return std::any_of(velocity_.begin(), velocity_.end(), [](double v) { return v != 0.0; });
}

void SimJacoArm::step(std::int64_t now_ns) noexcept {
  while (next_cycle_ns_ <= now_ns) {
    cycle(next_cycle_ns_);
    next_cycle_ns_ += jaco::ARM_PERIOD_NS;
  }
  now_ns_ = std::max(now_ns_, now_ns);
}

void SimJacoArm::cycle(std::int64_t t_ns) noexcept {
  ++counters_.cycles;
  run_delayed(t_ns);
  const jaco::JointAngles before = joints_;
  const bool button = joystick_.buttons[jaco::HOME_BUTTON] != 0;
  head_ran_ = false;
  desired_ = {};  // what no mode commands, the joints brake to
  toward_.reset();
  if (state_ != jaco::ArmState::NOINIT) {
    if (button) {
      run_button(t_ns);
    } else if (!run_axes()) {
      run_fifo(t_ns);
    }
  }
  integrate();
  move_fingers();
  if (head_ran_) finish_head(t_ns);
  bool moved = false;
  for (std::size_t j = 0; j < jaco::JOINTS; ++j) moved = moved || joints_[j] != before[j];
  if (moved) {
    last_motion_ns_ = t_ns;
    if (!button) state_ = jaco::ArmState::NORMAL;  // moved by the API, not by the HOME button
  }
  if (mode_ == SimJacoControlMode::CARTESIAN) { pose_ = pose_of(joints_); }
}

void SimJacoArm::run_button(std::int64_t t_ns) noexcept {
  using S = jaco::ArmState;
  if (transition_) {
    if (!move_toward(transition_target_)) return;
    transition_ = false;
    state_ = state_ == S::READY_TO_RETRACT ? S::RETRACT_STANDBY : S::READY_STANDBY;
    if (state_ == S::READY_STANDBY) standby_since_ns_ = t_ns;
    return;
  }
  // Still held at HOME: after a while the arm goes on toward RETRACT [I].
  const std::optional<std::int64_t>& hold = config_.held_home_to_retract_ns;
  if (state_ == S::READY_STANDBY && standby_since_ns_ && hold &&
      t_ns - *standby_since_ns_ >= *hold) {
    state_ = S::READY_TO_RETRACT;
    transition_ = true;
    transition_target_ = config_.retract_joints;
    standby_since_ns_.reset();
  }
}

bool SimJacoArm::run_axes() noexcept {
  const auto& a = joystick_.axes;
  if (std::all_of(a.begin(), a.end(), [](float v) { return v == 0.0F; })) return false;
  if (mode_ == SimJacoControlMode::ANGULAR) {
    std::array<double, jaco::JOINTS> speed{};
    for (std::size_t j = 0; j < jaco::JOINTS; ++j) {
      speed[j] = clamp_axis(a[j]) * config_.max_joint_speed_deg_s[j];
    }
    move_velocity(speed);
    return true;
  }
  // JACO.md 6.2: DSP >= 5 has wrist left/right on axis 3 and forth/back on 4; DSP < 5 swaps them
  // and negates the wrist rotation (axis 5).
  const bool dsp5 = config_.dsp.dsp5();
  const double wrist_left_right = clamp_axis(dsp5 ? a[3] : a[4]);
  const double wrist_forth_back = clamp_axis(dsp5 ? a[4] : a[3]);
  const double wrist_rotation = clamp_axis(a[5]) * (dsp5 ? 1.0 : -1.0);
  const Eigen::Vector3d linear =
      Eigen::Vector3d(clamp_axis(a[0]), clamp_axis(a[1]), clamp_axis(a[2])) *
      config_.max_linear_speed_m_s;
  const Eigen::Vector3d angular =
      Eigen::Vector3d(wrist_forth_back, wrist_left_right, wrist_rotation) *
      config_.max_angular_speed_rad_s;
  cartesian_step(linear, angular);
  return true;
}

void SimJacoArm::run_fifo(std::int64_t t_ns) noexcept {
  if (head_ == Head::NONE && !start_head(t_ns)) return;
  head_ran_ = true;
  const jaco::TrajectoryPoint& p = fifo_[fifo_head_];
  switch (head_) {
    case Head::POSITION:
      move_toward(head_target_);
      break;
    case Head::VELOCITY:
      if (p.type == jaco::PositionType::ANGULAR_VELOCITY) {
        std::array<double, jaco::JOINTS> speed{};
        for (std::size_t j = 0; j < jaco::JOINTS; ++j) speed[j] = p.target[j];
        move_velocity(speed);
      } else {
        cartesian_step(Eigen::Vector3d(p.target[0], p.target[1], p.target[2]),
                       Eigen::Vector3d(p.target[3], p.target[4], p.target[5]));
      }
      break;
    case Head::DELAY:
    case Head::IDLE:
    case Head::NONE:
      break;
  }
}

SimJacoArm::Head SimJacoArm::head_of(const jaco::TrajectoryPoint& p, std::int64_t t_ns) noexcept {
  switch (p.type) {
    case jaco::PositionType::ANGULAR_POSITION:
      for (std::size_t j = 0; j < jaco::JOINTS; ++j) head_target_[j] = p.target[j];
      return inside_limits(head_target_) ? Head::POSITION : Head::NONE;
    case jaco::PositionType::CARTESIAN_POSITION: {
      jaco::CartesianPose pose;
      pose.position = Eigen::Vector3d(p.target[0], p.target[1], p.target[2]);
      pose.theta = Eigen::Vector3d(p.target[3], p.target[4], p.target[5]);
      const auto ik = jaco::inverse_kinematics(jaco::to_transform(pose), joints_, limits_,
                                               IK_TOLERANCE, *geometry_);
      if (!ik) return Head::NONE;
      head_target_ = *ik;
      head_pose_ = pose;
      return Head::POSITION;
    }
    case jaco::PositionType::ANGULAR_VELOCITY:
    case jaco::PositionType::CARTESIAN_VELOCITY:
      return Head::VELOCITY;
    case jaco::PositionType::TIME_DELAY: {
      const double delay = std::clamp(static_cast<double>(p.delay_s), 0.0, MAX_DELAY_S);
      head_until_ns_ = t_ns + static_cast<std::int64_t>(std::llround(delay * 1e9));
      return Head::DELAY;
    }
    case jaco::PositionType::NO_MOVEMENT:
    default:
      return Head::IDLE;
  }
}

bool SimJacoArm::start_head(std::int64_t t_ns) noexcept {
  while (fifo_size_ > 0) {
    const jaco::TrajectoryPoint& p = fifo_[fifo_head_];
    head_pose_.reset();
    head_ = head_of(p, t_ns);
    if (head_ == Head::NONE) {  // outside the joint limits, or no IK solution
      ++counters_.points_rejected;
      pop_head();
      continue;
    }
    head_finger_velocity_ = p.hand_mode == jaco::HandMode::VELOCITY;
    for (std::size_t f = 0; f < jaco::FINGERS; ++f) {
      head_finger_speed_[f] = p.fingers[f];
      if (p.hand_mode == jaco::HandMode::POSITION) {
        finger_target_[f] = std::clamp(static_cast<double>(p.fingers[f]), 0.0, finger_max_);
      }
    }
    return true;
  }
  return false;
}

void SimJacoArm::finish_head(std::int64_t t_ns) noexcept {
  const jaco::TrajectoryPoint& p = fifo_[fifo_head_];
  bool done = true;
  if (head_ == Head::POSITION) {
    done = joints_ == head_target_ &&
           (p.hand_mode != jaco::HandMode::POSITION || fingers_ == finger_target_);
  } else if (head_ == Head::DELAY) {
    done = t_ns >= head_until_ns_;
  }
  if (!done) return;
  ++counters_.points_completed;
  pop_head();
}

void SimJacoArm::pop_head() noexcept {
  fifo_head_ = (fifo_head_ + 1) % fifo_.size();
  --fifo_size_;
  head_ = Head::NONE;
  head_pose_.reset();
  if (head_finger_velocity_) finger_target_ = fingers_;  // velocity-driven fingers stop
  head_finger_velocity_ = false;
}

void SimJacoArm::cartesian_step(const Eigen::Vector3d& linear,
                                const Eigen::Vector3d& angular) noexcept {
  const Eigen::Vector3d v = limit_norm(linear, config_.max_linear_speed_m_s);
  const Eigen::Vector3d w = limit_norm(angular, config_.max_angular_speed_rad_s);
  if (v.isZero(0.0) && w.isZero(0.0)) return;
  const Eigen::Isometry3d now = jaco::forward_kinematics(joints_, *geometry_);
  Eigen::Isometry3d target = now;
  target.translation() += v * DT_S;
  if (!w.isZero(0.0)) {
    target.linear() =
        Eigen::AngleAxisd(w.norm() * DT_S, w.normalized()).toRotationMatrix() * now.linear();
  }
  const auto ik = jaco::inverse_kinematics(target, joints_, limits_, IK_TOLERANCE, *geometry_);
  if (!ik) {
    ++counters_.ik_failures;  // no motion this cycle
    return;
  }
  move_toward(*ik);
}

void SimJacoArm::move_fingers() noexcept {
  const double max_step = finger_speed_ * DT_S;
  for (std::size_t f = 0; f < jaco::FINGERS; ++f) {
    const double before = fingers_[f];
    if (head_finger_velocity_ && head_ran_) {
      const double v = std::clamp(head_finger_speed_[f], -finger_speed_, finger_speed_);
      fingers_[f] = std::clamp(fingers_[f] + v * DT_S, 0.0, finger_max_);
      finger_target_[f] = fingers_[f];
    } else {
      const double error = finger_target_[f] - fingers_[f];
      fingers_[f] = std::abs(error) <= max_step ? finger_target_[f]
                                                : fingers_[f] + std::copysign(max_step, error);
    }
    if (finger_stop_ && fingers_[f] > before && fingers_[f] > *finger_stop_)
      fingers_[f] = std::max(before, *finger_stop_);  // closing against what is between them
    finger_velocity_[f] = (fingers_[f] - before) / DT_S;
  }
}

}  // namespace orthoflow::simulation
