// The execution manager (manipulation/execution_manager.hpp) driving the simulated JACO through its
// real controller, in lock step on simulated time (tests/drivers/jaco/jaco_test_rig.hpp), in a
// small world that reacts to the arm: a mug that follows the hand once the fingers close around it,
// seen by a perception stand-in that reports it every 33 ms with 30 ms of latency. A whole pick and
// place, then every abort: target moved, lost, stale perception, an obstacle while carrying, a
// missed grasp, the emergency stop, a refused command, a timeout, a person's stop.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "manipulation/execution_manager.hpp"
#include "manipulation/pick_place_job.hpp"
#include "tests/drivers/jaco/jaco_test_rig.hpp"
#include "tests/support/counting_new.hpp"  // the one TU of this binary that replaces operator new

namespace orthoflow::manipulation {
namespace {

using Eigen::AngleAxisd;
using Eigen::Vector3d;
namespace jaco = drivers::jaco;

ObjectBox mug() {
  ObjectBox box;
  box.base_from_object.translation() = Vector3d(0.30, -0.30, 0.05);
  box.extents = Vector3d(0.08, 0.08, 0.10);
  return box;
}
const Vector3d PLACE(0.05, -0.45, 0.05);

PickPlaceJob mug_job(const JobOptions& options = {}) {
  auto plan = plan_grasp(mug(), options.grasp);
  EXPECT_TRUE(plan && plan->best() != nullptr);
  auto job =
      make_pick_place_job(7, mug().base_from_object.translation(), *plan->best(), PLACE, options);
  EXPECT_TRUE(job) << (job ? "" : job.error());
  return *job;
}

/// The world around the arm, and the loop that runs the manager against it.
struct World {
  explicit World(jaco::ControllerOptions controller = {})
      : rig(test::JacoRig::home_config(), controller) {}
  test::JacoRig rig;
  Vector3d mug = ::orthoflow::manipulation::mug().base_from_object.translation();
  bool attached = false;
  bool slippery = false;  ///< the fingers never hold it
  /// The mug is rigid: around it, the fingers stop at the finger value `contact` (unset: half way
  /// from the job's open to its close, the mug's width).
  std::optional<double> contact;
  bool empty_hand = false;  ///< nothing between the fingers: they close to their goal
  Vector3d grip_offset = Vector3d::Zero();
  Vector3d seen_offset = Vector3d::Zero();  ///< perception's error on the mug's centre
  std::vector<Obstacle> obstacles;
  bool perceiving = true;   ///< false: perception stops (a dead camera)
  bool mug_visible = true;  ///< false: the mug's track is gone
  std::int64_t last_frame_ns = 0;
  PerceptionInput perception{};
  std::vector<ArmRequest> sent;
  int refusals = 0;
  std::uint64_t step_allocations = 0;  ///< operator new calls inside ExecutionManager::step
  /// Called every cycle before the manager's step (a test's event).
  std::function<void(World&, const ExecutionManager&)> event;

  Vector3d tool() const {
    return jaco::forward_kinematics(rig.controller->snapshot().joints).translation();
  }
  ArmInput arm_input() const { return manipulation::arm_input(rig.controller->snapshot()); }
  void update_world(const PickPlaceJob& job) {
    const auto s = rig.controller->snapshot();
    const bool around = (tool() - mug).norm() < 0.04;
    const double stop = contact.value_or(0.5 * (job.open_fingers + job.close_fingers));
    rig.arm().set_finger_stop(around && !empty_hand ? std::optional<double>(stop) : std::nullopt);
    const bool closed = s.fingers[0] >= stop - 50.0;
    if (!attached && closed && !slippery && !empty_hand && around) {
      attached = true;
      grip_offset = mug - tool();
    } else if (attached && !closed) {
      attached = false;
    }
    if (attached) mug = tool() + grip_offset;
  }
  void update_perception() {
    const std::int64_t now = rig.now();
    if (!perceiving || now - last_frame_ns < 33'000'000) return;
    last_frame_ns = now;
    perception.stamp_ns = now - 30'000'000;
    perception.target_seen = mug_visible;
    perception.target_centre = mug + seen_offset;
    perception.others = obstacles;
  }
  /// Runs @p job until the manager ends (or @p max_s of simulated time).
  void run(ExecutionManager& manager, const PickPlaceJob& job, double max_s = 120.0) {
    ASSERT_TRUE(manager.start(job, rig.now()));
    const std::int64_t end = rig.now() + static_cast<std::int64_t>(max_s * 1e9);
    while (rig.now() < end) {
      update_world(job);
      update_perception();
      if (event) event(*this, manager);
      const ArmInput input = arm_input();
      test::g_allocations.store(0);
      test::g_counting.store(true);  // the manager's step allocates nothing
      const ArmRequest r = manager.step(rig.now(), input, perception);
      test::g_counting.store(false);
      step_allocations += test::g_allocations.load();
      if (r.kind != ArmRequest::Kind::NONE) {
        sent.push_back(r);
        if (!rig.controller->submit(arm_command(r))) {
          ++refusals;
          manager.refused(rig.now());
        }
      }
      // The watchdog is fed while the manager runs, and not after: a finished job lets it expire.
      rig.cycle(manager.running());
      if (!manager.running() && r.kind == ArmRequest::Kind::NONE) break;
    }
  }
};

std::vector<Phase> phases_of(const ExecutionManager& m) {
  std::array<Decision, ExecutionManager::LOG_SIZE> log{};
  std::vector<Phase> out;
  const std::size_t n = m.decisions(log);
  for (std::size_t i = 0; i < n; ++i) out.push_back(log[i].to);
  return out;
}

std::string log_text(const ExecutionManager& m) {
  std::array<Decision, ExecutionManager::LOG_SIZE> log{};
  std::string out;
  const std::size_t n = m.decisions(log);
  for (std::size_t i = 0; i < n; ++i)
    out += std::to_string(double(log[i].stamp_ns - log[0].stamp_ns) * 1e-9).substr(0, 6) + " s  " +
           std::string(to_string(log[i].from)) + " -> " + to_string(log[i].to) + " (" +
           to_string(log[i].reason) + ": " + log[i].why + ")\n";
  return out;
}

double joint_distance(const jaco::JointAngles& a, const jaco::JointAngles& b) {
  double worst = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) worst = std::max(worst, std::fabs(a[j] - b[j]));
  return worst;
}

TEST(ExecutionManager, PicksAndPlacesTheMugOnTheSimulatedArm) {
  World world;
  ExecutionManager manager;
  const PickPlaceJob job = mug_job();
  world.run(manager, job);
  EXPECT_EQ(manager.phase(), Phase::DONE) << log_text(manager);
  EXPECT_EQ(manager.abort_reason(), AbortReason::NONE);
  std::printf("%s", log_text(manager).c_str());
  const std::vector<Phase> expected{
      Phase::GO_INITIAL, Phase::OPEN,  Phase::PRE_GRASP, Phase::APPROACH, Phase::CLOSE, Phase::LIFT,
      Phase::CARRY,      Phase::PLACE, Phase::RELEASE,   Phase::RETREAT,  Phase::DONE};
  EXPECT_EQ(phases_of(manager), expected) << log_text(manager);
  EXPECT_EQ(world.refusals, 0);
  EXPECT_EQ(world.step_allocations, 0U) << "no allocation in any of the 1850 steps";
  EXPECT_FALSE(world.attached) << "released";
  EXPECT_LT((world.mug - PLACE).norm(), 0.02) << "the mug stands at the place";
  EXPECT_LT(joint_distance(world.rig.controller->snapshot().joints, job.retreat), 1.0);
}

TEST(ExecutionManager, FingersStoppedByTheMugHaveClosedOnItAndTheJobGoesOn) {
  // A real hand closing to a goal narrower than the mug stops against it; the controller ends the
  // goal as blocked, and that is a closed hand.
  World world;
  ExecutionManager manager;
  const PickPlaceJob job = mug_job();
  world.contact = finger_for_opening(0.078, JobOptions{});
  ASSERT_LT(*world.contact, job.close_fingers - 500.0) << "the goal lies beyond the contact";
  world.run(manager, job);
  EXPECT_EQ(manager.phase(), Phase::DONE) << log_text(manager);
  EXPECT_NE(log_text(manager).find("close -> lift (none: the hand is closed on the object)"),
            std::string::npos)
      << log_text(manager);
  EXPECT_LT((world.mug - PLACE).norm(), 0.02) << "the mug stands at the place";
  EXPECT_EQ(world.step_allocations, 0U);
}

TEST(ExecutionManager, FingersBlockedRightWhereTheyStartAreNotAGrasp) {
  World world;
  ExecutionManager manager;
  const PickPlaceJob job = mug_job();
  world.contact = job.open_fingers + 0.1 * (job.touch_fingers - job.open_fingers);
  world.run(manager, job);
  EXPECT_EQ(manager.phase(), Phase::ABORTED) << log_text(manager);
  EXPECT_EQ(manager.abort_reason(), AbortReason::TIMEOUT) << log_text(manager);
  EXPECT_EQ(log_text(manager).find("close -> lift"), std::string::npos) << log_text(manager);
}

TEST(ExecutionManager, AWayInFromAboveGoesOverThenDownToThePreGrasp) {
  World world;
  ExecutionManager manager;
  PickPlaceJob job = mug_job();
  auto plan = plan_grasp(mug(), JobOptions{}.grasp);
  ASSERT_TRUE(plan && plan->best() != nullptr);
  ASSERT_TRUE(add_way_in_from_above(job, *plan->best(), 0.15, JobOptions{}));
  ASSERT_TRUE(job.via_above);
  const Vector3d above = jaco::forward_kinematics(job.above_pre_grasp).translation();
  const Vector3d pre = jaco::forward_kinematics(job.pre_grasp).translation();
  EXPECT_NEAR(above.z() - pre.z(), 0.15, 0.005);
  EXPECT_NEAR((above - pre).head<2>().norm(), 0.0, 0.005);
  double highest_near_pre = -1.0;  // the tool's height while above the pre-grasp's footprint
  world.event = [&](World& w, const ExecutionManager& m) {
    const Vector3d tool =
        jaco::forward_kinematics(w.rig.controller->snapshot().joints).translation();
    if (m.phase() == Phase::PRE_GRASP && (tool - pre).head<2>().norm() < 0.01)
      highest_near_pre = std::max(highest_near_pre, tool.z());
  };
  world.run(manager, job);
  EXPECT_EQ(manager.phase(), Phase::DONE) << log_text(manager);
  EXPECT_NE(log_text(manager).find("pre_grasp -> pre_grasp (none: above the pre-grasp pose)"),
            std::string::npos)
      << log_text(manager);
  EXPECT_GT(highest_near_pre, pre.z() + 0.14) << "the hand came down onto the pre-grasp";
  EXPECT_EQ(world.step_allocations, 0U);
}

TEST(ExecutionManager, AWayOutFromAboveRisesBeforeGoingToTheInitialPose) {
  World world;
  ExecutionManager manager;
  PickPlaceJob job = mug_job();
  const jaco::JointAngles start = world.rig.controller->snapshot().joints;
  ASSERT_TRUE(add_rise_first(job, start, 0.10, JobOptions{}));
  const Vector3d from = jaco::forward_kinematics(start).translation();
  const Vector3d risen = jaco::forward_kinematics(job.risen).translation();
  EXPECT_NEAR(risen.z() - from.z(), 0.10, 0.005);
  EXPECT_NEAR((risen - from).head<2>().norm(), 0.0, 0.005);
  world.run(manager, job);
  EXPECT_EQ(manager.phase(), Phase::DONE) << log_text(manager);
  const std::string log = log_text(manager);
  const std::size_t rose = log.find("go_initial -> go_initial (none: risen above where it was)");
  ASSERT_NE(rose, std::string::npos) << log;
  EXPECT_LT(rose, log.find("go_initial -> open")) << "it rises before it reaches the initial pose";
}

TEST(ExecutionManager, AWayRoundCarriesTheMugBesideTheMiddleOfItsLine) {
  World world;
  ExecutionManager manager;
  PickPlaceJob job = mug_job();
  auto plan = plan_grasp(mug(), JobOptions{}.grasp);
  ASSERT_TRUE(plan && plan->best() != nullptr);
  ASSERT_TRUE(add_way_round(job, *plan->best(), 0.15, JobOptions{}));
  const Vector3d aside = jaco::forward_kinematics(job.aside).translation();
  double nearest_aside = 1.0;  // how near the held mug's hand came to the way-point
  world.event = [&](World& w, const ExecutionManager& m) {
    const Vector3d tool =
        jaco::forward_kinematics(w.rig.controller->snapshot().joints).translation();
    if (m.phase() == Phase::CARRY && w.attached)
      nearest_aside = std::min(nearest_aside, (tool - aside).norm());
  };
  world.run(manager, job);
  EXPECT_EQ(manager.phase(), Phase::DONE) << log_text(manager);
  const std::string log = log_text(manager);
  const std::size_t beside = log.find("carry -> carry (none: beside what is in the way)");
  ASSERT_NE(beside, std::string::npos) << log;
  EXPECT_LT(beside, log.find("carry -> place")) << "beside it before above the place";
  EXPECT_LT(nearest_aside, 0.01) << "the hand, holding the mug, passed the way-point";
  EXPECT_LT((world.mug - PLACE).norm(), 0.02) << "the mug stands at the place";
  EXPECT_EQ(world.step_allocations, 0U);
}

TEST(ExecutionManager, TheTargetMovingDuringTheApproachBacksTheArmAway) {
  World world;
  ExecutionManager manager;
  const PickPlaceJob job = mug_job();
  world.event = [](World& w, const ExecutionManager& m) {
    if (m.phase() == Phase::APPROACH && !w.attached) w.mug.x() = 0.36;  // pushed 6 cm
  };
  world.run(manager, job);
  EXPECT_EQ(manager.phase(), Phase::ABORTED) << log_text(manager);
  EXPECT_EQ(manager.abort_reason(), AbortReason::TARGET_MOVED);
  EXPECT_EQ(phases_of(manager).back(), Phase::ABORTED);
  EXPECT_NE(std::find(phases_of(manager).begin(), phases_of(manager).end(), Phase::BACKING_AWAY),
            phases_of(manager).end());
  EXPECT_LT(joint_distance(world.rig.controller->snapshot().joints, job.pre_grasp), 1.0)
      << "backed away to the pre-grasp pose";
}

TEST(ExecutionManager, ACentreThatSinksUnderTheHandIsNotAMoveButALiftIs) {
  // The hand coming down hides the top of a partial view: its centre sinks 6 cm, the object stays.
  {
    World world;
    ExecutionManager manager;
    world.event = [](World& w, const ExecutionManager& m) {
      w.seen_offset.z() = m.phase() == Phase::APPROACH ? -0.06 : 0.0;
    };
    world.run(manager, mug_job());
    EXPECT_EQ(manager.phase(), Phase::DONE) << log_text(manager);
  }
  // A person lifts it 6 cm off the table.
  {
    World world;
    ExecutionManager manager;
    world.event = [](World& w, const ExecutionManager& m) {
      if (m.phase() == Phase::APPROACH && !w.attached)
        w.mug.z() = ::orthoflow::manipulation::mug().base_from_object.translation().z() + 0.06;
    };
    world.run(manager, mug_job());
    EXPECT_EQ(manager.abort_reason(), AbortReason::TARGET_MOVED) << log_text(manager);
  }
}

TEST(ExecutionManager, StalePerceptionStopsTheArmWhereItIs) {
  World world;
  ExecutionManager manager;
  const PickPlaceJob job = mug_job();
  std::int64_t stalled_at = 0;
  world.event = [&](World& w, const ExecutionManager& m) {
    if (m.phase() == Phase::APPROACH && w.perceiving) {
      w.perceiving = false;  // the camera dies halfway
      stalled_at = w.rig.now();
    }
  };
  world.run(manager, job);
  EXPECT_EQ(manager.phase(), Phase::ABORTED) << log_text(manager);
  EXPECT_EQ(manager.abort_reason(), AbortReason::PERCEPTION_STALE);
  EXPECT_EQ(world.sent.back().kind, ArmRequest::Kind::STOP);
  EXPECT_GT(joint_distance(world.rig.controller->snapshot().joints, job.grasp), 1.0)
      << "it never reached the grasp";
  // Frames come 30 ms late and every 33 ms: stale 300 ms after the last one, so the stop comes
  // within 400 ms of the camera's death.
  std::array<Decision, ExecutionManager::LOG_SIZE> log{};
  const std::size_t n = manager.decisions(log);
  EXPECT_LE(log[n - 1].stamp_ns - stalled_at, 400'000'000);
}

TEST(ExecutionManager, ALostTrackStopsTheArm) {
  World world;
  ExecutionManager manager;
  world.event = [](World& w, const ExecutionManager& m) {
    if (m.phase() == Phase::PRE_GRASP) w.mug_visible = false;
  };
  world.run(manager, mug_job());
  EXPECT_EQ(manager.abort_reason(), AbortReason::TARGET_LOST) << log_text(manager);
  EXPECT_EQ(manager.phase(), Phase::ABORTED);
}

TEST(ExecutionManager, ATargetHiddenByTheHandIsNotLost) {
  World world;
  ExecutionManager manager;
  world.event = [](World& w, const ExecutionManager& m) {
    // From the pre-grasp on, the camera sees only the hand where the mug is.
    if (m.phase() == Phase::PRE_GRASP) {
      w.mug_visible = false;
      w.perception.target_hidden = true;
    }
  };
  world.run(manager, mug_job());
  EXPECT_EQ(manager.phase(), Phase::DONE) << log_text(manager);
  EXPECT_EQ(manager.abort_reason(), AbortReason::NONE);
}

TEST(ExecutionManager, AnObstacleWhileCarryingStopsAndHolds) {
  World world;
  ExecutionManager manager;
  const PickPlaceJob job = mug_job();
  world.event = [&](World& w, const ExecutionManager& m) {
    if (m.phase() == Phase::CARRY && w.obstacles.empty()) {
      // A bowl put down on the way to the place.
      w.obstacles.push_back({0.5 * (w.mug + PLACE) + Vector3d(0, 0, 0.1), 0.06});
    }
  };
  world.run(manager, job);
  EXPECT_EQ(manager.abort_reason(), AbortReason::OBSTACLE) << log_text(manager);
  EXPECT_EQ(manager.phase(), Phase::ABORTED);
  EXPECT_TRUE(world.attached) << "the hand still holds the mug: never opened over an unknown place";
  EXPECT_EQ(world.sent.back().kind, ArmRequest::Kind::STOP);
}

TEST(ExecutionManager, AMissedGraspOpensAndBacksAway) {
  World world;
  world.slippery = true;
  ExecutionManager manager;
  const PickPlaceJob job = mug_job();
  world.run(manager, job);
  EXPECT_EQ(manager.abort_reason(), AbortReason::GRASP_MISSED) << log_text(manager);
  EXPECT_EQ(manager.phase(), Phase::ABORTED);
  EXPECT_LT(joint_distance(world.rig.controller->snapshot().joints, job.pre_grasp), 1.0);
  EXPECT_LT(world.rig.controller->snapshot().fingers[0], job.open_fingers + 100.0) << "opened";
}

TEST(ExecutionManager, AHandThatClosesToItsGoalHeldNothingAndBacksAway) {
  // Nothing between the fingers (the arm is off by a few centimetres: a bad calibration): they
  // reach their goal, narrower than the object, which a rigid object never lets them do.
  World world;
  world.empty_hand = true;
  ExecutionManager manager;
  const PickPlaceJob job = mug_job();
  world.run(manager, job);
  EXPECT_EQ(manager.abort_reason(), AbortReason::GRASP_MISSED) << log_text(manager);
  EXPECT_NE(log_text(manager).find("close -> backing_away (grasp_missed: the hand closed to its "
                                   "goal"),
            std::string::npos)
      << log_text(manager);
  EXPECT_EQ(manager.phase(), Phase::ABORTED);
  const std::vector<Phase> phases = phases_of(manager);
  EXPECT_EQ(std::count(phases.begin(), phases.end(), Phase::LIFT), 0) << "never lifted";
}

TEST(ExecutionManager, WithoutTheFingerCheckAClosedHandLiftsAndTheLiftCheckDecides) {
  // A simulated arm with no world between its fingers (`orthoflow task run --sim`) turns the
  // check off; the mug that does not rise with the hand is still a missed grasp, at the lift.
  World world;
  world.empty_hand = true;
  ExecutionLimits limits;
  limits.fingers_must_meet_the_object = false;
  ExecutionManager manager(limits);
  const PickPlaceJob job = mug_job();
  world.run(manager, job);
  EXPECT_EQ(manager.abort_reason(), AbortReason::GRASP_MISSED) << log_text(manager);
  EXPECT_NE(log_text(manager).find("the target did not rise with the hand"), std::string::npos)
      << log_text(manager);
}

TEST(ExecutionManager, TheEmergencyStopEndsTheJobWithNoFurtherCommand) {
  World world;
  ExecutionManager manager;
  std::size_t sent_before = 0;
  world.event = [&](World& w, const ExecutionManager& m) {
    if (m.phase() == Phase::CARRY && !w.rig.controller->snapshot().estop) {
      w.rig.controller->estop();
      sent_before = w.sent.size();
    }
  };
  world.run(manager, mug_job());
  EXPECT_EQ(manager.abort_reason(), AbortReason::ARM_ESTOP) << log_text(manager);
  EXPECT_EQ(manager.phase(), Phase::ABORTED);
  ASSERT_EQ(world.sent.size(), sent_before + 1);
  EXPECT_EQ(world.sent.back().kind, ArmRequest::Kind::STOP) << "only the stop";
}

TEST(ExecutionManager, ACommandTheSafetyLayerRefusesEndsTheJob) {
  // A keep-out box on the place, clear of the way to the mug (the monitor checks the whole arm
  // along every move): the controller refuses the carry.
  jaco::ControllerOptions controller;
  jaco::Box keep_out{{PLACE.x() - 0.02, PLACE.y() - 0.02, 0.0},
                     {PLACE.x() + 0.02, PLACE.y() + 0.02, 0.06},
                     core::FixedText<24>::from("the user's place")};
  ASSERT_TRUE(controller.limits.add_keep_out(keep_out));
  World world(controller);
  ExecutionManager manager;
  world.run(manager, mug_job());
  EXPECT_EQ(manager.abort_reason(), AbortReason::REFUSED) << log_text(manager);
  EXPECT_EQ(manager.phase(), Phase::ABORTED);
  EXPECT_EQ(world.refusals, 1);
  EXPECT_TRUE(world.attached) << "held, not dropped\n" << log_text(manager);
}

TEST(ExecutionManager, APhaseTimeoutStops) {
  World world;
  ExecutionLimits limits;
  limits.timeout_ns[static_cast<std::size_t>(Phase::PRE_GRASP)] = 200'000'000;  // too short
  ExecutionManager manager(limits);
  world.run(manager, mug_job());
  EXPECT_EQ(manager.abort_reason(), AbortReason::TIMEOUT) << log_text(manager);
  EXPECT_EQ(manager.phase(), Phase::ABORTED);
  EXPECT_EQ(world.sent.back().kind, ArmRequest::Kind::STOP);
}

TEST(ExecutionManager, APersonsStopDuringTheApproachBacksAway) {
  World world;
  ExecutionManager manager;
  bool asked = false;
  world.event = [&](World& w, const ExecutionManager& m) {
    if (m.phase() == Phase::APPROACH && !asked) {
      const_cast<ExecutionManager&>(m).request_stop(w.rig.now());
      asked = true;
    }
  };
  const PickPlaceJob job = mug_job();
  world.run(manager, job);
  EXPECT_EQ(manager.abort_reason(), AbortReason::STOP_REQUESTED) << log_text(manager);
  EXPECT_EQ(manager.phase(), Phase::ABORTED);
  EXPECT_LT(joint_distance(world.rig.controller->snapshot().joints, job.pre_grasp), 1.0);
}

TEST(ExecutionManager, NoPerceptionAtAllMeansNoMotion) {
  World world;
  world.perceiving = false;
  ExecutionManager manager;
  world.run(manager, mug_job());
  EXPECT_EQ(manager.abort_reason(), AbortReason::PERCEPTION_STALE);
  ASSERT_EQ(world.sent.size(), 2U) << "the initial move was decided at start; then the stop";
  EXPECT_EQ(world.sent.back().kind, ArmRequest::Kind::STOP);
}

TEST(PickPlaceJob, UnreachablePlacesAndNonFiniteInputsAreNamed) {
  auto plan = plan_grasp(mug(), GraspOptions{});
  ASSERT_TRUE(plan && plan->best());
  auto far = make_pick_place_job(1, mug().base_from_object.translation(), *plan->best(),
                                 Vector3d(2.0, 0.0, 0.05), JobOptions{});
  ASSERT_FALSE(far);
  EXPECT_EQ(far.error().rfind("carry: ", 0), 0U) << far.error();
  auto nan = make_pick_place_job(1, Vector3d(std::nan(""), 0, 0), *plan->best(), PLACE, {});
  EXPECT_FALSE(nan);
  EXPECT_NEAR(finger_for_opening(0.14, {}), 0.0, 1e-9);
  EXPECT_NEAR(finger_for_opening(0.0, {}), 6400.0, 1e-9);
}

}  // namespace
}  // namespace orthoflow::manipulation
