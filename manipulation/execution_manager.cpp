#include "manipulation/execution_manager.hpp"

#include "manipulation/segment_distance.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::manipulation {

ArmInput arm_input(const drivers::jaco::ArmSnapshot& s) noexcept {
  ArmInput a;
  a.joints = s.joints;
  a.fingers = {s.fingers[0], s.fingers[1], s.fingers[2]};
  a.idle = s.control == drivers::jaco::ControlState::IDLE && !s.fingers_moving;
  a.fingers_blocked = s.fingers_blocked;
  a.fault = s.fault;
  a.estop = s.estop;
  return a;
}

drivers::jaco::ArmCommand arm_command(const ArmRequest& r) noexcept {
  using Kind = drivers::jaco::ArmCommand::Kind;
  drivers::jaco::ArmCommand c;
  c.speed_fraction = r.speed_fraction;
  if (r.kind == ArmRequest::Kind::MOVE_JOINTS) {
    c.kind = Kind::MOVE_JOINTS;
    c.joints = r.joints;
  } else if (r.kind == ArmRequest::Kind::MOVE_FINGERS) {
    c.kind = Kind::MOVE_FINGERS;
    c.fingers = {r.fingers, r.fingers, r.fingers};
  } else {
    c.kind = Kind::STOP;
  }
  return c;
}

namespace {

using drivers::jaco::JointAngles;

/// The tool point at sample @p s of JOINT_PATH_SAMPLES along the joint-space segment.
Eigen::Vector3d tool_along(const JointAngles& from, const JointAngles& to, std::size_t s) noexcept {
  const double t = static_cast<double>(s) / static_cast<double>(JOINT_PATH_SAMPLES);
  JointAngles q{};
  for (std::size_t j = 0; j < q.size(); ++j) q[j] = from[j] + t * (to[j] - from[j]);
  return drivers::jaco::forward_kinematics(q).translation();
}

ArmRequest move_to(const JointAngles& joints, double speed) noexcept {
  ArmRequest r;
  r.kind = ArmRequest::Kind::MOVE_JOINTS;
  r.joints = joints;
  r.speed_fraction = speed;
  return r;
}

ArmRequest fingers_to(double fingers, double speed) noexcept {
  ArmRequest r;
  r.kind = ArmRequest::Kind::MOVE_FINGERS;
  r.fingers = fingers;
  r.speed_fraction = speed;
  return r;
}

ArmRequest stop_now() noexcept {
  ArmRequest r;
  r.kind = ArmRequest::Kind::STOP;
  return r;
}

}  // namespace

const char* to_string(Phase phase) noexcept {
  switch (phase) {
    case Phase::IDLE:
      return "idle";
    case Phase::GO_INITIAL:
      return "go_initial";
    case Phase::OPEN:
      return "open";
    case Phase::PRE_GRASP:
      return "pre_grasp";
    case Phase::APPROACH:
      return "approach";
    case Phase::CLOSE:
      return "close";
    case Phase::LIFT:
      return "lift";
    case Phase::CARRY:
      return "carry";
    case Phase::PLACE:
      return "place";
    case Phase::RELEASE:
      return "release";
    case Phase::RETREAT:
      return "retreat";
    case Phase::DONE:
      return "done";
    case Phase::BACKING_AWAY:
      return "backing_away";
    case Phase::ABORTED:
      return "aborted";
  }
  return "unknown";
}

const char* to_string(AbortReason reason) noexcept {
  switch (reason) {
    case AbortReason::NONE:
      return "none";
    case AbortReason::TIMEOUT:
      return "timeout";
    case AbortReason::PERCEPTION_STALE:
      return "perception_stale";
    case AbortReason::TARGET_LOST:
      return "target_lost";
    case AbortReason::TARGET_MOVED:
      return "target_moved";
    case AbortReason::OBSTACLE:
      return "obstacle";
    case AbortReason::ARM_FAULT:
      return "arm_fault";
    case AbortReason::ARM_ESTOP:
      return "arm_estop";
    case AbortReason::REFUSED:
      return "refused";
    case AbortReason::GRASP_MISSED:
      return "grasp_missed";
    case AbortReason::STOP_REQUESTED:
      return "stop_requested";
  }
  return "unknown";
}

bool ExecutionManager::start(const PickPlaceJob& job, std::int64_t now_ns) noexcept {
  if (running()) return false;
  job_ = job;
  reason_ = AbortReason::NONE;
  back_away_after_open_ = false;
  stop_requested_ = false;
  target_last_seen_ns_ = now_ns;
  logged_ = 0;
  pending_ = enter(Phase::GO_INITIAL, now_ns, AbortReason::NONE, "job started");
  return true;
}

bool ExecutionManager::holding() const noexcept {
  return phase_ == Phase::LIFT || phase_ == Phase::CARRY || phase_ == Phase::PLACE;
}

std::size_t ExecutionManager::decisions(std::span<Decision> out) const noexcept {
  const std::size_t kept = std::min(logged_, LOG_SIZE);
  const std::size_t first = logged_ - kept;
  const std::size_t n = std::min(kept, out.size());
  for (std::size_t i = 0; i < n; ++i) out[i] = log_[(first + i) % LOG_SIZE];
  return n;
}

ArmRequest ExecutionManager::enter(Phase next, std::int64_t now_ns, AbortReason reason,
                                   const char* why) noexcept {
  log_[logged_ % LOG_SIZE] = Decision{now_ns, phase_, next, reason, why};
  ++logged_;
  phase_ = next;
  entered_ns_ = now_ns;
  const double slow = limits_.approach_speed;
  switch (next) {
    case Phase::GO_INITIAL:
      risen_reached_ = !job_.rise_first;
      return risen_reached_ ? move_to(job_.initial, 1.0) : move_to(job_.risen, slow);
    case Phase::OPEN:
      return fingers_to(job_.open_fingers, 1.0);
    case Phase::PRE_GRASP:
      above_reached_ = !job_.via_above;
      return move_to(above_reached_ ? job_.pre_grasp : job_.above_pre_grasp, 1.0);
    case Phase::APPROACH:
      return move_to(job_.grasp, slow);
    case Phase::CLOSE:
      return fingers_to(job_.close_fingers, 1.0);
    case Phase::LIFT:
      return move_to(job_.lift, slow);
    case Phase::CARRY:
      aside_reached_ = !job_.via_aside;
      return move_to(aside_reached_ ? job_.carry : job_.aside, 0.5);
    case Phase::PLACE:
      return move_to(job_.place, slow);
    case Phase::RELEASE:
      return fingers_to(job_.open_fingers, 1.0);
    case Phase::RETREAT:
      return move_to(job_.retreat, slow);
    case Phase::BACKING_AWAY:
      return back_away_after_open_ ? fingers_to(job_.open_fingers, 1.0)
                                   : move_to(job_.pre_grasp, slow);
    case Phase::ABORTED:
      return stop_now();
    case Phase::IDLE:
    case Phase::DONE:
      return {};
  }
  return {};
}

ArmRequest ExecutionManager::abort(std::int64_t now_ns, AbortReason reason,
                                   const char* why) noexcept {
  reason_ = reason;
  const bool hard = reason == AbortReason::ARM_FAULT || reason == AbortReason::ARM_ESTOP ||
                    reason == AbortReason::REFUSED;
  // Back away only from near the object, before it is held, with perception to trust, and not
  // from a retreat that is itself in doubt.
  const bool near_object = phase_ == Phase::APPROACH || phase_ == Phase::CLOSE ||
                           (phase_ == Phase::LIFT && reason == AbortReason::GRASP_MISSED);
  if (!hard && near_object && reason != AbortReason::PERCEPTION_STALE &&
      reason != AbortReason::OBSTACLE) {
    back_away_after_open_ = phase_ != Phase::APPROACH;  // the hand closed, or was closing
    const ArmRequest r = enter(Phase::BACKING_AWAY, now_ns, reason, why);
    return r;
  }
  return enter(Phase::ABORTED, now_ns, reason, why);  // stop and hold where it is
}

void ExecutionManager::note(std::int64_t now_ns, const char* why) noexcept {
  log_[logged_ % LOG_SIZE] = Decision{now_ns, phase_, phase_, AbortReason::NONE, why};
  ++logged_;
}

void ExecutionManager::refused(std::int64_t now_ns) noexcept {
  if (running()) pending_ = abort(now_ns, AbortReason::REFUSED, "the arm refused the command");
}

void ExecutionManager::request_stop(std::int64_t now_ns) noexcept {
  if (!running()) return;
  stop_requested_ = true;
  stop_requested_ns_ = now_ns;
}

const JointAngles* ExecutionManager::joint_goal(Phase phase) const noexcept {
  switch (phase) {
    case Phase::GO_INITIAL:
      return risen_reached_ ? &job_.initial : &job_.risen;
    case Phase::PRE_GRASP:
      return above_reached_ ? &job_.pre_grasp : &job_.above_pre_grasp;
    case Phase::APPROACH:
      return &job_.grasp;
    case Phase::LIFT:
      return &job_.lift;
    case Phase::CARRY:
      return aside_reached_ ? &job_.carry : &job_.aside;
    case Phase::PLACE:
      return &job_.place;
    case Phase::RETREAT:
      return &job_.retreat;
    case Phase::BACKING_AWAY:
      return back_away_after_open_ ? nullptr : &job_.pre_grasp;
    default:
      return nullptr;
  }
}

bool ExecutionManager::at_joints(const ArmInput& arm, const JointAngles& goal) const noexcept {
  if (!arm.idle) return false;
  for (std::size_t j = 0; j < goal.size(); ++j) {
    if (!(std::fabs(arm.joints[j] - goal[j]) <= limits_.joint_tolerance_deg)) return false;
  }
  return true;
}

bool ExecutionManager::at_fingers(const ArmInput& arm, double goal) const noexcept {
  if (!arm.idle) return false;
  for (double f : arm.fingers) {
    if (!(std::fabs(f - goal) <= limits_.finger_tolerance)) return false;
  }
  return true;
}

bool ExecutionManager::closed_beyond_open(const ArmInput& arm) const noexcept {
  // Stopped on the way, each finger past a quarter of the way from open to the goal (not blocked
  // right where it started).
  const double quarter = job_.open_fingers + 0.25 * (job_.close_fingers - job_.open_fingers);
  for (double f : arm.fingers) {
    if (!(f >= quarter)) return false;
  }
  return true;
}

bool ExecutionManager::moved(const Eigen::Vector3d& seen) const noexcept {
  const Eigen::Vector3d d = seen - job_.target_centre;
  const double rise = d.dot(job_.up);
  return (d - rise * job_.up).norm() > limits_.target_moved_m || rise > limits_.target_moved_m;
}

bool ExecutionManager::path_blocked(const ArmInput& arm,
                                    std::span<const Obstacle> others) const noexcept {
  const JointAngles* goal = joint_goal(phase_);
  if (goal == nullptr || others.empty()) return false;
  return joint_path_blocked(arm.joints, *goal, others, limits_.obstacle_clearance_m);
}

bool joint_path_blocked(const JointAngles& from, const JointAngles& to,
                        std::span<const Obstacle> others, double clearance_m) noexcept {
  if (others.empty()) return false;
  Eigen::Vector3d previous = tool_along(from, to, 0);
  for (std::size_t s = 1; s <= JOINT_PATH_SAMPLES; ++s) {
    const Eigen::Vector3d point = tool_along(from, to, s);
    if (segment_blocked(previous, point, others, clearance_m)) return true;
    previous = point;
  }
  return false;
}

double joint_path_deviation(const JointAngles& from, const JointAngles& to) noexcept {
  const Eigen::Vector3d a = tool_along(from, to, 0);
  const Eigen::Vector3d b = tool_along(from, to, JOINT_PATH_SAMPLES);
  double worst = 0.0;
  for (std::size_t s = 1; s < JOINT_PATH_SAMPLES; ++s)
    worst = std::max(worst, distance_to_segment(a, b, tool_along(from, to, s)));
  return worst;
}

bool segment_blocked(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                     std::span<const Obstacle> others, double clearance_m) noexcept {
  for (const Obstacle& o : others) {
    if (distance_to_segment(from, to, o.centre) < o.radius + clearance_m) return true;
  }
  return false;
}

ArmRequest ExecutionManager::step(std::int64_t now_ns, const ArmInput& arm,
                                  const PerceptionInput& perception) noexcept {
  if (pending_.kind != ArmRequest::Kind::NONE) {  // decided outside a step (start, refused)
    const ArmRequest r = pending_;
    pending_ = {};
    return r;
  }
  if (!running()) return {};
  // The arm first: nothing moves on a faulted or stopped arm.
  if (arm.fault) return abort(now_ns, AbortReason::ARM_FAULT, "the arm reports a fault");
  if (arm.estop) return abort(now_ns, AbortReason::ARM_ESTOP, "the emergency stop is latched");
  if (stop_requested_ && phase_ != Phase::BACKING_AWAY) {
    stop_requested_ = false;
    return abort(now_ns, AbortReason::STOP_REQUESTED, "a stop was requested");
  }
  // The stale-perception interlock: no motion on an old view of the world.
  if (perception.stamp_ns == 0 || now_ns - perception.stamp_ns > limits_.perception_max_age_ns)
    return abort(now_ns, AbortReason::PERCEPTION_STALE, "perception is older than its limit");
  const bool before_hold =
      phase_ == Phase::PRE_GRASP || phase_ == Phase::APPROACH || phase_ == Phase::CLOSE;
  if (perception.target_seen || perception.target_hidden)
    target_last_seen_ns_ = std::max(target_last_seen_ns_, perception.stamp_ns);
  if (before_hold) {
    if (now_ns - target_last_seen_ns_ > limits_.target_lost_ns)
      return abort(now_ns, AbortReason::TARGET_LOST, "the target's track is gone");
    if (perception.target_seen && moved(perception.target_centre))
      return abort(now_ns, AbortReason::TARGET_MOVED, "the target moved from the planned place");
  }
  if (path_blocked(arm, perception.others))
    return abort(now_ns, AbortReason::OBSTACLE, "another object is near the hand's path");
  const std::int64_t timeout = limits_.timeout_ns[static_cast<std::size_t>(phase_)];
  if (timeout > 0 && now_ns - entered_ns_ > timeout)
    return abort(now_ns, AbortReason::TIMEOUT, "the phase took longer than its limit");
  // Success checks: each operator ends on the arm's state (and the lift on perception).
  switch (phase_) {
    case Phase::GO_INITIAL:
      if (!risen_reached_ && at_joints(arm, job_.risen)) {
        risen_reached_ = true;
        note(now_ns, "risen above where it was");
        return move_to(job_.initial, 1.0);
      }
      if (risen_reached_ && at_joints(arm, job_.initial))
        return enter(Phase::OPEN, now_ns, {}, "at the initial pose");
      break;
    case Phase::OPEN:
      if (at_fingers(arm, job_.open_fingers))
        return enter(Phase::PRE_GRASP, now_ns, {}, "the hand is open");
      break;
    case Phase::PRE_GRASP:
      if (!above_reached_ && at_joints(arm, job_.above_pre_grasp)) {
        above_reached_ = true;
        note(now_ns, "above the pre-grasp pose");
        return move_to(job_.pre_grasp, limits_.approach_speed);
      }
      if (above_reached_ && at_joints(arm, job_.pre_grasp))
        return enter(Phase::APPROACH, now_ns, {}, "at the pre-grasp pose");
      break;
    case Phase::APPROACH:
      if (at_joints(arm, job_.grasp)) return enter(Phase::CLOSE, now_ns, {}, "at the grasp pose");
      break;
    case Phase::CLOSE:
      if (at_fingers(arm, job_.close_fingers))
        return enter(Phase::LIFT, now_ns, {}, "the hand is closed");
      // A rigid object stops the fingers short of a goal narrower than it: closed on it.
      if (arm.idle && arm.fingers_blocked && closed_beyond_open(arm))
        return enter(Phase::LIFT, now_ns, {}, "the hand is closed on the object");
      break;
    case Phase::LIFT:
      if (at_joints(arm, job_.lift)) {
        // The object must have risen with the hand (if the hand does not hide it).
        if (perception.target_seen &&
            perception.target_centre.z() - job_.target_centre.z() < job_.lift_m / 2)
          return abort(now_ns, AbortReason::GRASP_MISSED, "the target did not rise with the hand");
        return enter(Phase::CARRY, now_ns, {}, "lifted");
      }
      break;
    case Phase::CARRY:
      if (!aside_reached_ && at_joints(arm, job_.aside)) {
        aside_reached_ = true;
        note(now_ns, "beside what is in the way");
        return move_to(job_.carry, 0.5);
      }
      if (aside_reached_ && at_joints(arm, job_.carry))
        return enter(Phase::PLACE, now_ns, {}, "above the place");
      break;
    case Phase::PLACE:
      if (at_joints(arm, job_.place)) return enter(Phase::RELEASE, now_ns, {}, "placed");
      break;
    case Phase::RELEASE:
      if (at_fingers(arm, job_.open_fingers)) return enter(Phase::RETREAT, now_ns, {}, "released");
      break;
    case Phase::RETREAT:
      if (at_joints(arm, job_.retreat)) return enter(Phase::DONE, now_ns, {}, "retreated: done");
      break;
    case Phase::BACKING_AWAY:
      if (back_away_after_open_) {
        if (at_fingers(arm, job_.open_fingers)) {
          back_away_after_open_ = false;
          return move_to(job_.pre_grasp, limits_.approach_speed);
        }
      } else if (at_joints(arm, job_.pre_grasp)) {
        return enter(Phase::ABORTED, now_ns, reason_, "backed away to the pre-grasp pose");
      }
      break;
    default:
      break;
  }
  return {};
}

}  // namespace orthoflow::manipulation
