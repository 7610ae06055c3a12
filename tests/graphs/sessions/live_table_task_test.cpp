// A table task on a live arm (graphs/sessions/live_table_task.hpp): what `orthoflow task run` does,
// here in lock step with the simulated JACO behind its real driver (simulation/sim_jaco_transport,
// the documented protocol) and object lists as a running graph publishes them. A start command
// plans the task and the arm moves; a stop command makes the running job back away and the task
// end, and nothing moves after that; every refusal says why; what the arm publishes is what the
// robot-body filter reads.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "drivers/jaco/jaco_controller.hpp"
#include "drivers/jaco/jaco_link.hpp"
#include "graphs/sessions/live_table_task.hpp"
#include "graphs/sessions/table_task_session.hpp"
#include "simulation/devices/sim_jaco_transport.hpp"

namespace orthoflow::graphs {
namespace {

namespace jaco = drivers::jaco;
using Eigen::Isometry3d;
using Eigen::Vector3d;

constexpr std::int64_t MS = 1'000'000;

/// The simulated arm, the task, and the stream of object lists, on simulated time.
class LiveRig {
 public:
  LiveRig() {
    simulation::SimJacoConfig arm;
    arm.start_state = jaco::ArmState::READY_STANDBY;
    sim_.add_arm(std::move(arm));
    sim_.run_for(std::chrono::seconds(1));
    auto devices = jaco::list_arms(sim_);
    EXPECT_TRUE(devices && !devices.value().empty());
    auto opened = jaco::JacoController::open(sim_, devices.value().front());
    EXPECT_TRUE(opened);
    arm_ = std::move(opened).value();
    base_from_camera_ = synthetic_base_from_camera(simulation::TableSpec{});
    LiveTaskSettings settings;
    settings.options.base_from_camera = base_from_camera_;
    settings.options.limits = TableTaskConfig::default_limits();
    // No world here (the objects are lists): nothing stops the simulated fingers, as in `orthoflow
    // task run --sim`.
    settings.options.limits.fingers_must_meet_the_object = false;
    LiveTaskPorts ports;
    ports.snapshot = [this] { return arm_->snapshot(); };
    ports.submit = [this](const jaco::ArmCommand& c) {
      submitted.push_back(c);
      return arm_->submit(c).has_value();
    };
    ports.keep_alive = [this] { arm_->keep_alive(); };
    ports.publish_state = [this](const engine::ArmStatePayload& p) { states.push_back(p); };
    ports.publish_status = [this](const TaskStatus& s) { statuses.push_back(s); };
    ports.known = [this] { return known; };
    task = std::make_unique<LiveTableTask>(std::move(settings), std::move(ports));
  }

  /// An upright bottle-sized box (7 x 7 x 20 cm) whose centre is @p base_centre, as the graph
  /// reports it: its frame and box in the camera frame.
  void add_object(std::uint64_t track, const char* label, const Vector3d& base_centre) {
    engine::ObjectEntry& e = list_->objects[list_->count++];
    e = engine::ObjectEntry{};
    e.track_id = track;
    e.label.assign(label);
    e.unknown = label[0] == '\0' ? 1U : 0U;
    Isometry3d base_from_object = Isometry3d::Identity();
    base_from_object.translation() = base_centre;
    const Isometry3d object_from_camera = base_from_object.inverse() * base_from_camera_;
    const Eigen::Matrix4d m = object_from_camera.matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) e.frame[4 * r + c] = static_cast<float>(m(r, c));
    e.bbox[0] = 0.07F;
    e.bbox[1] = 0.07F;
    e.bbox[2] = 0.20F;
    e.flags = engine::OBJECT_DESCRIBED;
  }

  void clear_objects() { list_->count = 0; }

  [[nodiscard]] std::int64_t now() const { return sim_.clock().now_ns(); }

  /// @p ms of arm cycles; an object list (stamped now) every 100 ms.
  void run(std::int64_t ms) {
    for (std::int64_t k = 0; k < ms / 10; ++k) {
      if (frames && ticks_++ % 10 == 0) {
        list_->host_stamp_ns = now();
        task->on_objects(*list_);
      }
      task->tick(now());
      arm_->cycle();
      next_ns_ = std::max(next_ns_ + 10 * MS, now());
      sim_.run_for(std::chrono::nanoseconds(next_ns_ - now()));
    }
  }

  TaskAnswer send(TaskCommand::Kind kind,
                  manipulation::TableTaskKind what = manipulation::TableTaskKind::CLEAR_TABLE,
                  std::vector<std::string> bring = {}) {
    RemoteTaskCommand c;
    c.client = 7;
    c.request = ++request_;
    c.command.kind = kind;
    c.command.task = what;
    c.command.bring = std::move(bring);
    return task->command(c, now());
  }

  [[nodiscard]] jaco::ArmSnapshot snapshot() const { return arm_->snapshot(); }

  std::unique_ptr<LiveTableTask> task;
  std::vector<jaco::ArmCommand> submitted;
  std::vector<engine::ArmStatePayload> states;
  std::vector<TaskStatus> statuses;
  std::vector<std::string> known;
  bool frames = true;
  simulation::SimJacoTransport sim_;

 private:
  std::unique_ptr<jaco::JacoController> arm_;
  Isometry3d base_from_camera_ = Isometry3d::Identity();
  std::unique_ptr<engine::ObjectListPayload> list_ = [] {
    auto p = std::make_unique<engine::ObjectListPayload>();
    p->reset_header();
    return p;
  }();
  std::uint64_t request_ = 0;
  std::uint64_t ticks_ = 0;
  std::int64_t next_ns_ = 0;
};

double joint_change(const jaco::ArmSnapshot& a, const jaco::ArmSnapshot& b) {
  return jaco::max_joint_error(a.joints, b.joints);
}

TEST(LiveTableTask, AStartMovesTheArmAndAStopBacksItAwayAndEndsTheTask) {
  LiveRig rig;
  rig.add_object(3, "bottle", Vector3d(-0.20, -0.40, 0.10));
  rig.run(500);
  const jaco::ArmSnapshot before = rig.snapshot();
  ASSERT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::STARTED);
  EXPECT_EQ(rig.statuses.back().answer, TaskAnswer::STARTED);
  EXPECT_EQ(rig.statuses.back().request, 1U);
  EXPECT_EQ(rig.statuses.back().state, TaskState::RUNNING);
  EXPECT_EQ(rig.statuses.back().moves, 1U);
  rig.run(3000);  // on its way to the pre-grasp
  ASSERT_TRUE(rig.task->running()) << rig.task->runner()->moves()[0].failure;
  EXPECT_GT(joint_change(before, rig.snapshot()), 5.0) << "the arm moves on the start";
  const manipulation::Phase phase = rig.task->runner()->manager().phase();
  EXPECT_TRUE(phase == manipulation::Phase::PRE_GRASP || phase == manipulation::Phase::OPEN)
      << manipulation::to_string(phase);
  // A second start while it runs is refused, and nothing changes.
  EXPECT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::REFUSED);
  EXPECT_EQ(rig.statuses.back().message, "a task is running: clear_table");
  ASSERT_EQ(rig.send(TaskCommand::Kind::STOP), TaskAnswer::STOPPING);
  rig.run(15000);
  EXPECT_FALSE(rig.task->running());
  const manipulation::TableTaskRunner& runner = *rig.task->runner();
  EXPECT_EQ(runner.stopped(), "stopped by a stop command");
  ASSERT_EQ(runner.moves().size(), 1U);
  EXPECT_FALSE(runner.moves()[0].done);
  EXPECT_EQ(runner.moves()[0].failure, "stop_requested");
  EXPECT_EQ(rig.statuses.back().state, TaskState::FINISHED);
  EXPECT_EQ(rig.statuses.back().message, "stopped by a stop command");
  // At rest, and nothing is sent to the arm any more.
  const jaco::ArmSnapshot rest = rig.snapshot();
  EXPECT_EQ(rest.control, jaco::ControlState::IDLE);
  const std::size_t sent = rig.submitted.size();
  rig.run(2000);
  EXPECT_EQ(rig.submitted.size(), sent);
  EXPECT_LT(joint_change(rest, rig.snapshot()), 1e-6);
  // A stop with no task running is refused; the task can be started again.
  EXPECT_EQ(rig.send(TaskCommand::Kind::STOP), TaskAnswer::REFUSED);
  EXPECT_EQ(rig.statuses.back().message, "no task is running");
  EXPECT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::STARTED);
}

TEST(LiveTableTask, AFailedMoveIsTriedOnceMoreAtTheEndThenTheTaskEnds) {
  LiveRig rig;
  rig.add_object(3, "bottle", Vector3d(-0.20, -0.40, 0.10));
  rig.run(300);
  ASSERT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::STARTED);
  rig.clear_objects();  // someone takes the bottle away before the arm gets there
  rig.run(100);
  ASSERT_TRUE(rig.task->running());
  rig.run(4000);  // the move looks for it 30 frames; then its retry does, 30 more
  rig.run(4000);
  EXPECT_FALSE(rig.task->running());
  const auto& moves = rig.task->runner()->moves();
  ASSERT_EQ(moves.size(), 2U);
  EXPECT_EQ(moves[0].failure, "the object is no longer seen");
  EXPECT_EQ(moves[1].attempt, 2U);
  EXPECT_EQ(moves[1].retry_of, 0U);
  EXPECT_EQ(moves[1].to, moves[0].to);  // to the same spot
  EXPECT_EQ(moves[1].failure, "the object is no longer seen");
  EXPECT_EQ(rig.task->runner()->stopped(), "");  // the task ended, it was not stopped
  EXPECT_EQ(rig.statuses.back().state, TaskState::FINISHED);
  EXPECT_EQ(rig.statuses.back().moves, 2U);
}

TEST(LiveTableTask, AJobWhoseObjectStillStandsWhereItWasHasLeftItBehindAndIsRetried) {
  // The bottle here never moves, whatever the hand does (a grasp that missed it while the hand hid
  // it from the lift check): the manager finishes its job, but the object stands where it was,
  // not at its spot. The move is failed, not done, and tried once more.
  LiveRig rig;
  rig.add_object(3, "bottle", Vector3d(-0.20, -0.40, 0.10));
  rig.run(300);
  ASSERT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::STARTED);
  for (int k = 0; k < 60 && rig.task->running(); ++k) rig.run(5000);
  ASSERT_FALSE(rig.task->running());
  const auto& moves = rig.task->runner()->moves();
  ASSERT_EQ(moves.size(), 2U);
  for (const auto& m : moves) {
    EXPECT_FALSE(m.done);
    EXPECT_EQ(m.failure, "left behind: the object still stands where it was");
    EXPECT_NE(m.decisions.back().find("retreat -> done"), std::string::npos)
        << "the manager's own job ended: " << m.decisions.back();
  }
  EXPECT_EQ(moves[1].retry_of, 0U);
}

TEST(LiveTableTask, ATwinLeftStandingBesideTheLiftedObjectIsNotTakenForIt) {
  // Two cans side by side (demo seed 4). When the hand has lifted the first out of the camera's
  // view, the second still stands 12 cm from where the first stood, under a new track (the tracker
  // lost it while the arm hid it). It is where the other can stood when the move started, not where
  // the target did: the lift check must not take it for the target ("did not rise": grasp_missed).
  LiveRig rig;
  const Vector3d first(-0.20, -0.40, 0.10), second(-0.20, -0.52, 0.10);
  rig.add_object(3, "can", first);
  rig.add_object(4, "can", second);
  rig.run(300);
  ASSERT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::STARTED);
  using manipulation::Phase;
  for (int k = 0; k < 6000 && rig.task->runner()->manager().phase() != Phase::LIFT; ++k)
    rig.run(10);
  ASSERT_EQ(rig.task->runner()->manager().phase(), Phase::LIFT);
  EXPECT_EQ(rig.task->runner()->move_index(), 0U);
  rig.clear_objects();
  rig.add_object(9, "can", second);
  for (int k = 0; k < 600 && rig.task->runner()->move_index() == 0; ++k) rig.run(100);
  const auto& moves = rig.task->runner()->moves();
  ASSERT_GE(moves.size(), 2U);
  EXPECT_TRUE(moves[0].done) << moves[0].failure;
  EXPECT_EQ(moves[0].failure, "");
}

TEST(LiveTableTask, AStartWithoutFreshObjectsIsRefused) {
  LiveRig rig;
  rig.frames = false;
  rig.run(200);
  EXPECT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::REFUSED);
  EXPECT_EQ(rig.statuses.back().message, "no fresh objects from the graph");
  rig.frames = true;
  rig.add_object(3, "bottle", Vector3d(-0.20, -0.40, 0.10));
  rig.run(200);
  rig.frames = false;  // the graph stops publishing
  rig.run(1500);
  EXPECT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::REFUSED);
  EXPECT_EQ(rig.task->runner(), nullptr);
  EXPECT_TRUE(rig.submitted.empty()) << "nothing was sent to the arm";
}

TEST(LiveTableTask, ServeAMealOfACategoryNobodyTaughtIsRefused) {
  LiveRig rig;
  rig.add_object(3, "bottle", Vector3d(-0.20, -0.40, 0.10));
  rig.run(300);
  rig.known = {"bottle"};
  EXPECT_EQ(rig.send(TaskCommand::Kind::START, manipulation::TableTaskKind::SERVE_A_MEAL, {"mug"}),
            TaskAnswer::REFUSED);
  EXPECT_EQ(rig.statuses.back().message, "nobody taught the category 'mug'");
  EXPECT_FALSE(rig.task->running());
  EXPECT_EQ(
      rig.send(TaskCommand::Kind::START, manipulation::TableTaskKind::SERVE_A_MEAL, {"bottle"}),
      TaskAnswer::STARTED);
  EXPECT_EQ(rig.task->runner()->moves().size(), 1U);
}

TEST(LiveTableTask, UnknownObjectsAndTableItemsStayAndTheTaskEndsAtOnce) {
  LiveRig rig;
  rig.add_object(3, "", Vector3d(-0.20, -0.40, 0.10));
  rig.add_object(4, "plate", Vector3d(0.0, -0.45, 0.10));
  rig.run(300);
  ASSERT_EQ(rig.send(TaskCommand::Kind::START), TaskAnswer::STARTED);
  rig.run(100);
  EXPECT_FALSE(rig.task->running());
  ASSERT_EQ(rig.task->runner()->stays().size(), 2U);
  EXPECT_TRUE(rig.submitted.empty());
  EXPECT_EQ(rig.statuses.back().state, TaskState::FINISHED);
}

TEST(LiveTableTask, EveryCycleStreamsTheArmStateTheBodyFilterReads) {
  LiveRig rig;
  rig.run(500);
  ASSERT_EQ(rig.states.size(), 50U);
  const engine::ArmStatePayload& p = rig.states.back();
  EXPECT_EQ(p.type_id, engine::ARM_STATE_TYPE_ID);
  EXPECT_EQ(p.version, engine::ARM_STATE_VERSION);
  EXPECT_EQ(p.held_m[6], 0.0) << "nothing held";
  const jaco::ArmSnapshot s = rig.snapshot();
  EXPECT_NEAR(p.joints_deg[0], s.joints[0], 1.0);
  // Statuses go out periodically even with nothing to answer.
  EXPECT_GE(rig.statuses.size(), 2U);
  EXPECT_EQ(rig.statuses.back().state, TaskState::IDLE);
}

TEST(LiveTableTask, ObjectsWithNonFiniteFramesOrBoxesAreNotPlannedWith) {
  engine::ObjectListPayload list;
  std::memset(static_cast<void*>(&list), 0, sizeof list);
  list.reset_header();
  list.count = 3;
  for (std::uint32_t k = 0; k < 3; ++k) {
    list.objects[k] = engine::ObjectEntry{};
    list.objects[k].track_id = k + 1;
    list.objects[k].flags = engine::OBJECT_DESCRIBED;
    list.objects[k].frame[0] = list.objects[k].frame[5] = list.objects[k].frame[10] =
        list.objects[k].frame[15] = 1.0F;
    list.objects[k].bbox[0] = list.objects[k].bbox[1] = list.objects[k].bbox[2] = 0.1F;
  }
  list.objects[1].frame[3] = std::numeric_limits<float>::quiet_NaN();
  list.objects[2].bbox[2] = std::numeric_limits<float>::infinity();
  std::vector<manipulation::SeenObject> seen;
  seen_objects(list, Isometry3d::Identity(), manipulation::SupportPlane{}, seen);
  ASSERT_EQ(seen.size(), 1U);
  EXPECT_EQ(seen[0].track, 1U);
  list.count = 1000;  // a count beyond the capacity reads the capacity, no further
  seen_objects(list, Isometry3d::Identity(), manipulation::SupportPlane{}, seen);
  EXPECT_LE(seen.size(), engine::OBJECT_LIST_CAPACITY);
}

}  // namespace
}  // namespace orthoflow::graphs
