// The path checks of issue 21's closed loop: the tool's path of a joint-space move is the forward
// kinematics of the straight joint-space segment (the controller's synchronised profile), not the
// straight line between its ends; and every move of a pick-and-place job is checked along it, for
// other objects and for the driver's safety limits, before the job starts.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "manipulation/execution_manager.hpp"
#include "manipulation/pick_place_job.hpp"

namespace orthoflow::manipulation {
namespace {

using Eigen::Vector3d;
namespace jaco = drivers::jaco;

jaco::JointAngles turned(jaco::JointAngles q, double base_deg) {
  q[0] += base_deg;
  return q;
}

Vector3d tool_at(const jaco::JointAngles& from, const jaco::JointAngles& to, double t) {
  jaco::JointAngles q{};
  for (std::size_t j = 0; j < q.size(); ++j) q[j] = from[j] + t * (to[j] - from[j]);
  return jaco::forward_kinematics(q).translation();
}

TEST(JointPath, FollowsTheArcNotTheChord) {
  // The base turns 120 degrees: the tool sweeps an arc about the base; the chord between the ends
  // cuts across, far inside the arc.
  const jaco::JointAngles from = jaco::HOME_JOINTS;
  const jaco::JointAngles to = turned(from, 120.0);
  const Vector3d a = tool_at(from, to, 0.0), b = tool_at(from, to, 1.0);
  const Vector3d on_arc = tool_at(from, to, 0.5);
  const Vector3d on_chord = 0.5 * (a + b);
  ASSERT_GT((on_arc - on_chord).norm(), 0.15) << "the arc sags well away from the chord";
  const std::array<Obstacle, 1> at_arc{{{on_arc, 0.03}}};
  const std::array<Obstacle, 1> at_chord{{{on_chord, 0.03}}};
  EXPECT_TRUE(joint_path_blocked(from, to, at_arc, 0.02));
  EXPECT_FALSE(segment_blocked(a, b, at_arc, 0.02)) << "the straight check misses it";
  EXPECT_FALSE(joint_path_blocked(from, to, at_chord, 0.02)) << "the arm never goes there";
  EXPECT_TRUE(segment_blocked(a, b, at_chord, 0.02));
}

TEST(JointPath, EmptyObstaclesAndAStillMove) {
  const jaco::JointAngles q = jaco::HOME_JOINTS;
  EXPECT_FALSE(joint_path_blocked(q, turned(q, 90.0), {}, 0.02));
  const Vector3d tool = jaco::forward_kinematics(q).translation();
  const std::array<Obstacle, 1> near{{{tool + Vector3d(0.0, 0.0, 0.04), 0.01}}};
  EXPECT_TRUE(joint_path_blocked(q, q, near, 0.035)) << "standing still next to it";
  EXPECT_FALSE(joint_path_blocked(q, q, near, 0.025));
}

ObjectBox mug() {
  ObjectBox box;
  box.base_from_object.translation() = Vector3d(0.30, -0.30, 0.05);
  box.extents = Vector3d(0.08, 0.08, 0.10);
  return box;
}

PickPlaceJob mug_job() {
  const JobOptions options;
  auto plan = plan_grasp(mug(), options.grasp);
  EXPECT_TRUE(plan && plan->best() != nullptr);
  auto job = make_pick_place_job(7, mug().base_from_object.translation(), *plan->best(),
                                 Vector3d(0.05, -0.45, 0.05), options);
  EXPECT_TRUE(job) << (job ? "" : job.error());
  return *job;
}

TEST(JobPaths, AClearJobPassesAndAnObjectOnTheCarryIsNamed) {
  const PickPlaceJob job = mug_job();
  const jaco::SafetyLimits limits;
  EXPECT_TRUE(check_job_paths(job, jaco::HOME_JOINTS, {}, 0.02, limits));
  // A bottle where the carry's arc passes, not on the straight line from lift to carry.
  const std::array<Obstacle, 1> on_carry{{{tool_at(job.lift, job.carry, 0.5), 0.01}}};
  const auto blocked = check_job_paths(job, jaco::HOME_JOINTS, on_carry, 0.01, limits);
  ASSERT_FALSE(blocked);
  EXPECT_EQ(blocked.error().rfind("carry: ", 0), 0U) << blocked.error();
}

TEST(JobPaths, TheFirstBlockedMoveIsNamedInOrder) {
  const PickPlaceJob job = mug_job();
  // An object right at the pre-grasp pose blocks the way in before anything later.
  const Vector3d pre = jaco::forward_kinematics(job.pre_grasp).translation();
  const std::array<Obstacle, 1> at_pre{{{pre, 0.02}}};
  const auto blocked = check_job_paths(job, jaco::HOME_JOINTS, at_pre, 0.02, jaco::SafetyLimits{});
  ASSERT_FALSE(blocked);
  EXPECT_EQ(blocked.error().rfind("pre_grasp: ", 0), 0U) << blocked.error();
}

TEST(JobPaths, AWayInFromAboveIsCheckedOverAndDown) {
  PickPlaceJob job = mug_job();
  const JobOptions options;
  auto plan = plan_grasp(mug(), options.grasp);
  ASSERT_TRUE(plan && plan->best() != nullptr);
  ASSERT_TRUE(add_way_in_from_above(job, *plan->best(), 0.15, options));
  const jaco::SafetyLimits limits;
  EXPECT_TRUE(check_job_paths(job, jaco::HOME_JOINTS, {}, 0.02, limits));
  // Something between the raised pose and the pre-grasp blocks the way down, and is named so.
  const Vector3d down = tool_at(job.above_pre_grasp, job.pre_grasp, 0.5);
  const std::array<Obstacle, 1> under{{{down, 0.01}}};
  const auto blocked = check_job_paths(job, jaco::HOME_JOINTS, under, 0.01, limits);
  ASSERT_FALSE(blocked);
  EXPECT_EQ(blocked.error().rfind("above the pre_grasp: ", 0) == 0 ||
                blocked.error().rfind("down to the pre_grasp: ", 0) == 0,
            true)
      << blocked.error();
  // A height the arm cannot reach is refused and leaves the job as it was.
  PickPlaceJob direct = mug_job();
  EXPECT_FALSE(add_way_in_from_above(direct, *plan->best(), 2.0, options));
  EXPECT_FALSE(direct.via_above);
  EXPECT_FALSE(add_way_in_from_above(direct, *plan->best(), -0.1, options));
}

TEST(JobPaths, AWayOutFromAboveIsCheckedUpThenAcross) {
  PickPlaceJob job = mug_job();
  const jaco::JointAngles now = job.pre_grasp;  // the hand low, where a last job may leave it
  ASSERT_TRUE(add_rise_first(job, now, 0.15, JobOptions{}));
  const jaco::SafetyLimits limits;
  EXPECT_TRUE(check_job_paths(job, now, {}, 0.02, limits));
  const std::array<Obstacle, 1> over{{{tool_at(now, job.risen, 0.5), 0.01}}};
  const auto blocked = check_job_paths(job, now, over, 0.01, limits);
  ASSERT_FALSE(blocked);
  EXPECT_EQ(blocked.error().rfind("rise: ", 0), 0U) << blocked.error();
  EXPECT_FALSE(add_rise_first(job, now, 0.0, JobOptions{}));
}

TEST(JobPaths, AWayRoundPassesBesideWhatBlocksTheCarry) {
  const JobOptions options;
  auto plan = plan_grasp(mug(), options.grasp);
  ASSERT_TRUE(plan && plan->best() != nullptr);
  const PickPlaceJob direct = mug_job();
  const jaco::SafetyLimits limits;
  // Something in the middle of the carry's line blocks the direct carry.
  const Vector3d middle = tool_at(direct.lift, direct.carry, 0.5);
  const std::array<Obstacle, 1> in_the_way{{{middle, 0.02}}};
  const auto blocked = check_job_paths(direct, jaco::HOME_JOINTS, in_the_way, 0.02, limits);
  ASSERT_FALSE(blocked);
  EXPECT_EQ(blocked.error().rfind("carry: ", 0), 0U) << blocked.error();
  // A way round on either side passes it: its way-point is at the carry height, beside the
  // middle of the carry's line (positive side: left of the way, seen from above).
  for (const double side : {0.15, -0.15}) {
    PickPlaceJob job = direct;
    ASSERT_TRUE(add_way_round(job, *plan->best(), side, options)) << side;
    ASSERT_TRUE(job.via_aside);
    const Vector3d from = jaco::forward_kinematics(job.lift).translation();
    const Vector3d to = jaco::forward_kinematics(job.carry).translation();
    const Vector3d aside = jaco::forward_kinematics(job.aside).translation();
    EXPECT_NEAR(aside.z(), 0.5 * (from.z() + to.z()), 0.005);
    const Vector3d along = (to - from).normalized();
    const Vector3d left = Vector3d::UnitZ().cross(along);
    EXPECT_NEAR((aside - 0.5 * (from + to)).dot(left), side, 0.005) << side;
    EXPECT_TRUE(check_job_paths(job, jaco::HOME_JOINTS, in_the_way, 0.02, limits)) << side;
    // Something on the way to the way-point, or on from it, blocks it and is named so.
    const std::array<Obstacle, 1> first{{{tool_at(job.lift, job.aside, 0.5), 0.01}}};
    const auto to_aside = check_job_paths(job, jaco::HOME_JOINTS, first, 0.01, limits);
    ASSERT_FALSE(to_aside);
    EXPECT_EQ(to_aside.error().rfind("carry: ", 0), 0U) << to_aside.error();
    const std::array<Obstacle, 1> second{{{tool_at(job.aside, job.carry, 0.5), 0.01}}};
    const auto on = check_job_paths(job, jaco::HOME_JOINTS, second, 0.01, limits);
    ASSERT_FALSE(on);
    EXPECT_EQ(on.error().rfind("carry on from beside: ", 0), 0U) << on.error();
  }
  // No side, an unreachable side, or a carry with no length is refused; the job stays direct.
  PickPlaceJob job = direct;
  EXPECT_FALSE(add_way_round(job, *plan->best(), 0.0, options));
  EXPECT_FALSE(add_way_round(job, *plan->best(), 3.0, options));
  EXPECT_FALSE(add_way_round(job, *plan->best(), std::nan(""), options));
  job.carry = job.lift;
  EXPECT_FALSE(add_way_round(job, *plan->best(), 0.15, options));
  EXPECT_FALSE(job.via_aside);
}

TEST(JobPaths, AMoveTheSafetyLayerWouldRefuseIsNamed) {
  const PickPlaceJob job = mug_job();
  jaco::SafetyLimits limits;
  // A keep-out box around the grasp pose only: the driver would refuse the approach mid-job.
  const Vector3d grasp = jaco::forward_kinematics(job.grasp).translation();
  ASSERT_TRUE(
      limits.add_keep_out({grasp - Vector3d::Constant(0.01), grasp + Vector3d::Constant(0.01),
                           core::FixedText<24>::from("fixture")}));
  const auto refused = check_job_paths(job, jaco::HOME_JOINTS, {}, 0.02, limits);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().rfind("approach: ", 0), 0U) << refused.error();
  EXPECT_NE(refused.error().find("fixture"), std::string::npos) << refused.error();
}

TEST(JobPaths, AStraightMoveOnAnotherIkBranchIsRefused) {
  PickPlaceJob job = mug_job();
  EXPECT_LT(joint_path_deviation(job.carry, job.place), MAX_SWING_M)
      << "the planned place is straight";
  // The same place pose's tool point reached with the wrist turned round: the ends are near, the
  // way between them swings through the scene.
  job.place = job.carry;
  job.place[3] += 150.0;
  job.place[4] -= 100.0;
  ASSERT_GT(joint_path_deviation(job.carry, job.place), MAX_SWING_M);
  jaco::SafetyLimits limits;
  limits.workspace.min.z() = -1.0;  // the swing alone, not the table's floor
  const auto refused = check_job_paths(job, jaco::HOME_JOINTS, {}, 0.02, limits);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().rfind("place: the hand would swing", 0), 0U) << refused.error();
}

TEST(JobPaths, ANonFiniteJobIsRefused) {
  PickPlaceJob job = mug_job();
  job.carry[2] = std::nan("");
  const auto refused = check_job_paths(job, jaco::HOME_JOINTS, {}, 0.02, jaco::SafetyLimits{});
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().rfind("carry: ", 0), 0U) << refused.error();
}

TEST(PickPlaceJob, ARetreatOutOfReachBackwardsRisesInstead) {
  // Places along a line from near to far: a side grasp retreats back along its approach, unless
  // the arm cannot reach that; then the open hand rises off the object by the same distance.
  const JobOptions options;
  auto plan = plan_grasp(mug(), options.grasp);
  ASSERT_TRUE(plan);
  std::size_t backwards = 0, upwards = 0;
  for (std::size_t k = 0; k < plan->feasible_count; ++k) {
    const Grasp& g = plan->feasible[k];
    if (g.kind == GraspKind::TOP) continue;
    for (double x = -0.8; x <= 0.8; x += 0.1) {
      for (double y = -0.8; y <= 0.8; y += 0.1) {
        const Vector3d place(x, y, mug().base_from_object.translation().z());
        auto job = make_pick_place_job(7, mug().base_from_object.translation(), g, place, options);
        if (!job) continue;
        const Vector3d at_place = jaco::forward_kinematics(job->place).translation();
        const Vector3d back = jaco::forward_kinematics(job->retreat).translation() - at_place;
        if ((back + options.grasp.pre_grasp_distance_m * g.approach.normalized()).norm() < 0.005)
          ++backwards;
        else if ((back - Vector3d(0, 0, options.grasp.pre_grasp_distance_m)).norm() < 0.005)
          ++upwards;
        else
          ADD_FAILURE() << "a retreat neither back nor up at " << x << ", " << y;
      }
    }
  }
  EXPECT_GT(backwards, 0U);
  EXPECT_GT(upwards, 0U) << "no place needed the rising retreat: the test shows nothing";
}

}  // namespace
}  // namespace orthoflow::manipulation
