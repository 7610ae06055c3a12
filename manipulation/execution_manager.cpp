// The execution manager's state machine (manipulation/execution_manager.hpp): a job started, each
// phase entered with its request to the arm, aborts (backing away or holding), and step(), which
// decides every cycle. Its checks are in execution_checks.cpp; the names of its phases and its
// conversions to the driver's types in execution_io.cpp.
#include "manipulation/execution_manager.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::manipulation {

namespace {

using drivers::jaco::JointAngles;

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
      if (at_fingers(arm, job_.close_fingers)) {
        if (limits_.fingers_must_meet_the_object)
          return abort(now_ns, AbortReason::GRASP_MISSED,
                       "the hand closed to its goal: nothing of the object's width between the "
                       "fingers");
        return enter(Phase::LIFT, now_ns, {}, "the hand is closed");
      }
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
