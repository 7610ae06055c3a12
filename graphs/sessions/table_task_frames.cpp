// The table task's frames (graphs/sessions/table_task_session.hpp): what happens between two
// frames in lock step: the newest objects to the runner, the stages (settle, teach, recognise,
// task, finish), the arm's 100 Hz cycles with the world following the gripper, the scripted
// event, and the next frame rendered with the arm in it. The set-up is in table_task_session.cpp.
#include <algorithm>
#include <chrono>
#include <span>
#include <vector>

#include "drivers/jaco/jaco_link.hpp"
#include "graphs/sessions/live_table_task.hpp"
#include "graphs/sessions/task_session.hpp"
#include "manipulation/grasp_planner.hpp"

namespace orthoflow::graphs {

void TaskLoop::take_objects() noexcept {
  bool got = false;
  while (objects_->poll(list_)) got = true;
  if (!got || perception_dead_) return;
  seen_objects(list_, robot_base_from_camera_, job_options_.grasp.table, seen_);
  runner_->on_objects(seen_, list_.host_stamp_ns);
}

void TaskLoop::teach() {
  const simulation::Scene& scene = world_->scene();
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    LearningCommand c;
    c.kind = LearningCommand::Kind::TEACH;
    c.by_position = true;
    const simulation::Vec3 p = world_->centre(i);
    c.position = {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
    (void)c.label.try_assign(simulation::category_name(scene.objects[i].model.category));
    if (teacher_->send(c) != 0) ++teaches_sent_;
  }
}

void TaskLoop::fire_event() {
  const manipulation::ExecutionManager& manager = runner_->manager();
  if (event_fired_ || config_.event == TaskEvent::NONE || runner_->move_index() != 0 ||
      runner_->state() != manipulation::TableTaskRunner::State::RUNNING || !manager.running() ||
      manager.phase() != config_.event_phase)
    return;
  event_fired_ = true;
  switch (config_.event) {
    case TaskEvent::MOVE_TARGET: {
      const int index = world_->find(static_cast<std::uint32_t>(std::max(target_object_, 0)));
      if (index >= 0) {
        const simulation::PlacedObject& o =
            world_->scene().objects[static_cast<std::size_t>(index)];
        (void)world_->move_object(static_cast<std::size_t>(index), o.table_x + 0.10, o.table_y);
      }
      break;
    }
    case TaskEvent::STOP_PERCEPTION:
      perception_dead_ = true;
      break;
    case TaskEvent::UNPLUG_ARM:
      sim_.unplug(0);
      break;
    default:
      break;
  }
}

void TaskLoop::arm_cycle() noexcept {
  const jaco::ArmSnapshot s = arm_->snapshot();
  const Isometry3d hand = camera_from_base_ * jaco::forward_kinematics(s.joints);
  const Vector3d tool = hand.translation();
  simulation::HandAxes axes{};
  for (int k = 0; k < 3; ++k)
    axes[static_cast<std::size_t>(k)] = {hand.linear()(0, k), hand.linear()(1, k),
                                         hand.linear()(2, k)};
  const std::size_t spills = world_->spills(), drops = world_->drops();
  world_->update({tool.x(), tool.y(), tool.z()},
                 manipulation::opening_for_finger(s.fingers[0], job_options_), axes);
  const bool running = runner_->state() == manipulation::TableTaskRunner::State::RUNNING;
  if (running && runner_->move_index() < report_.moves.size()) {
    // The world's account of the carry, checked at the arm's 100 Hz.
    MoveReport& move = report_.moves[runner_->move_index()];
    move.max_tilt_deg = std::max(move.max_tilt_deg, world_->held_tilt_deg());
    move.spilled = move.spilled || world_->spills() > spills;
    move.dropped = move.dropped || world_->drops() > drops;
  }
  // What is between the fingers stops them (a rigid object): the hand stalls on it, or closes
  // on nothing to its goal. The fingers close along the hand's y axis (grasp_planner's
  // hand_pose: column 1 is the closing direction).
  const std::optional<double> width = world_->grip_width({tool.x(), tool.y(), tool.z()}, axes[1]);
  if (sim_.present(0))
    sim_.arm(0).set_finger_stop(
        width ? std::optional<double>(manipulation::finger_for_opening(*width, job_options_))
              : std::nullopt);
  if (running && world_->held() >= 0 &&
      static_cast<int>(world_->scene().objects[static_cast<std::size_t>(world_->held())].id) ==
          target_object_)
    report_.moves[runner_->move_index()].held = true;
  manipulation::HeldObject held;
  (void)runner_->held(held);  // the body filter removes it with the arm
  arm_states_.write(arm_state_payload(s, now(), held));
  fire_event();
  if (runner_->cycle(now(), s, submit_)) arm_->keep_alive();
  arm_->cycle();
  next_cycle_ns_ += jaco::ARM_PERIOD_NS;
  if (now() < next_cycle_ns_) sim_.run_for(std::chrono::nanoseconds(next_cycle_ns_ - now()));
  next_cycle_ns_ = std::max(next_cycle_ns_, now());
}

void TaskLoop::advance_stage() {
  using State = manipulation::TableTaskRunner::State;
  switch (stage_) {
    case Stage::SETTLE:
      if (frame_ >= config_.settle_frames) {
        teach();
        stage_ = Stage::TEACH;
        stage_frame_ = frame_;
      }
      break;
    case Stage::TEACH: {
      LearningAck ack;
      while (teacher_->poll(ack)) {
        ++acks_;
        if (ack.outcome == LearningAck::Outcome::LEARNED ||
            ack.outcome == LearningAck::Outcome::STORED)
          ++report_.taught;
      }
      if (acks_ >= teaches_sent_ || frame_ - stage_frame_ > 30) {
        stage_ = Stage::RECOGNISE;
        stage_frame_ = frame_;
      }
      break;
    }
    case Stage::RECOGNISE:
      if (frame_ - stage_frame_ >= config_.recognise_frames) {
        plan_task();
        stage_ = report_.refused.empty() ? Stage::TASK : Stage::END;
      }
      break;
    case Stage::TASK:
      runner_->step(now(), arm_->snapshot(), submit_);
      if (runner_->state() == State::FINISHED) {
        stage_ = Stage::FINISH;
        stage_frame_ = frame_;
      }
      break;
    case Stage::FINISH:
      if (frame_ - stage_frame_ >= 5) stage_ = Stage::END;
      break;
    case Stage::END:
      break;
  }
}

const simulation::Scene* TaskLoop::next_frame(kernels::PointCloud& cloud) noexcept {
  take_objects();
  if (config_.on_frame && frame_ > 0) {
    TaskFrameView view;
    view.frame = frame_ - 1;
    view.seconds = 1e-9 * static_cast<double>(now() - TASK_LOOP_START_NS);
    view.scene = &world_->scene();
    view.base_from_camera = &base_from_camera_;
    const int held = world_->held();
    view.held_object_id =
        held >= 0 ? static_cast<int>(world_->scene().objects[static_cast<std::size_t>(held)].id)
                  : -1;
    view.phase = manipulation::to_string(runner_->manager().phase());
    config_.on_frame(view);
  }
  advance_stage();
  if (stage_ == Stage::END) return nullptr;
  if (1e-9 * static_cast<double>(now() - TASK_LOOP_START_NS) > config_.max_seconds) {
    report_.stopped = "the simulated time limit was reached";
    runner_->halt(now());
    stage_ = Stage::END;
    return nullptr;
  }
  const std::int64_t end = now() + config_.frame_period_ns;
  while (now() < end) arm_cycle();
  if (stage_ == Stage::TASK) {
    runner_->finish_step(now());
    if (runner_->state() == manipulation::TableTaskRunner::State::FINISHED) {
      report_.stopped = runner_->stopped();
      stage_ = Stage::FINISH;
      stage_frame_ = frame_;
    }
  }
  // The arm as the camera sees it: the link model without the filter's margin.
  const jaco::JointAngles joints = arm_->snapshot().joints;
  manipulation::ArmBodyModel body;
  body.margin_m = 0.0;
  const std::size_t n = manipulation::arm_body_capsules(joints, base_from_camera_, body,
                                                        jaco::jaco2_geometry(), capsules_);
  // Where the robot believes its arm is in the image (its calibration): the runner adds the
  // filter's margin.
  const std::size_t m = manipulation::arm_body_capsules(joints, robot_base_from_camera_, body,
                                                        jaco::jaco2_geometry(), robot_capsules_);
  runner_->on_arm_body(std::span(robot_capsules_).first(m));
  std::vector<simulation::BodyCapsule>& robot = world_->robot();
  robot.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const kernels::Capsule& c = capsules_[i];
    robot[i] = {{c.a[0], c.a[1], c.a[2]}, {c.b[0], c.b[1], c.b[2]}, c.radius};
  }
  simulation::render_scene(world_->scene(), render_, rng_, cloud);
  cloud.info.frame_id = frame_;
  cloud.info.sensor_stamp_ns = now();
  cloud.info.host_stamp_ns = now();
  ++frame_;
  return &world_->scene();
}

}  // namespace orthoflow::graphs
