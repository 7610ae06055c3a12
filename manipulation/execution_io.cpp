// The execution manager's words for the outside (manipulation/execution_manager.hpp): the names of
// its phases and abort reasons, and the conversions between the driver's snapshot and command and
// the manager's input and request. The state machine is in execution_manager.cpp.
#include "manipulation/execution_manager.hpp"

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

}  // namespace orthoflow::manipulation
