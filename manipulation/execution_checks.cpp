// What the execution manager checks every cycle (manipulation/execution_manager.hpp): a phase's
// joint goal and whether the arm reached it, the fingers, whether the target moved, and whether
// another object blocks the hand's path (the joint-space path checks, also used to plan). The
// state machine is in execution_manager.cpp.
#include "manipulation/execution_manager.hpp"

#include "manipulation/segment_distance.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::manipulation {

namespace {

using drivers::jaco::JointAngles;

/// The tool point at sample @p s of JOINT_PATH_SAMPLES along the joint-space segment.
Eigen::Vector3d tool_along(const JointAngles& from, const JointAngles& to, std::size_t s) noexcept {
  const double t = static_cast<double>(s) / static_cast<double>(JOINT_PATH_SAMPLES);
  JointAngles q{};
  for (std::size_t j = 0; j < q.size(); ++j) q[j] = from[j] + t * (to[j] - from[j]);
  return drivers::jaco::forward_kinematics(q).translation();
}

}  // namespace

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
  // Stopped on the way, each finger past where the object begins (not blocked right where it
  // started).
  for (double f : arm.fingers) {
    if (!(f >= job_.touch_fingers)) return false;
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

}  // namespace orthoflow::manipulation
