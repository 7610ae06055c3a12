// The grasp planner (manipulation/grasp_planner.hpp) on hand-made boxes and frames: pre-grasp
// distance, approach axis, finger opening, the orientation constraint, the IK solutions, and every
// rejection reason.
#include "manipulation/grasp_planner.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

namespace orthoflow::manipulation {
namespace {

using Eigen::AngleAxisd;
using Eigen::Isometry3d;
using Eigen::Vector3d;

constexpr double DEG = std::numbers::pi / 180.0;

ObjectBox box_at(const Vector3d& centre, const Vector3d& extents, double yaw_rad = 0.0) {
  ObjectBox box;
  box.base_from_object.linear() = AngleAxisd(yaw_rad, Vector3d::UnitZ()).toRotationMatrix();
  box.base_from_object.translation() = centre;
  box.extents = extents;
  return box;
}
// A mug-sized box standing on the table (z = 0), in the arm's comfortable workspace.
ObjectBox mug(double yaw_rad = 0.0) {
  return box_at({0.30, -0.30, 0.05}, {0.08, 0.08, 0.10}, yaw_rad);
}

GraspPlan plan_of(const ObjectBox& box, const GraspOptions& options = {}) {
  const auto plan = plan_grasp(box, options);
  EXPECT_TRUE(plan.has_value()) << (plan.has_value() ? "" : to_string(plan.error()));
  return plan.has_value() ? plan.value() : GraspPlan{};
}

bool has_rejection(const GraspPlan& plan, GraspRejection reason) {
  for (std::size_t i = 0; i < plan.rejected_count; ++i) {
    if (plan.rejected[i].reason == reason) { return true; }
  }
  return false;
}

TEST(GraspPlanner, PreGraspLiesTheThesisDistanceBackAlongTheApproach) {
  const GraspPlan plan = plan_of(mug());
  ASSERT_GT(plan.feasible_count, 0U);
  for (std::size_t i = 0; i < plan.feasible_count; ++i) {
    const Grasp& g = plan.feasible[i];
    const Vector3d step = g.grasp.translation() - g.pre_grasp.translation();
    EXPECT_NEAR(step.norm(), 0.15, 1e-12);
    EXPECT_NEAR(step.normalized().dot(g.approach), 1.0, 1e-12);
    EXPECT_NEAR((g.grasp.linear().col(2) - g.approach).norm(), 0.0, 1e-12)
        << "the hand's z is the approach";
    EXPECT_TRUE(g.pre_grasp.linear().isApprox(g.grasp.linear())) << "a straight approach";
  }
}

TEST(GraspPlanner, ATallObjectPrefersASideGraspAndAFlatOneATopGrasp) {
  const GraspPlan tall = plan_of(mug());
  EXPECT_EQ(tall.preferred, GraspKind::SIDE);
  ASSERT_NE(tall.best(), nullptr);
  EXPECT_EQ(tall.best()->kind, GraspKind::SIDE);
  const GraspPlan low = plan_of(box_at({0.30, -0.30, 0.03}, {0.10, 0.06, 0.06}));
  EXPECT_EQ(low.preferred, GraspKind::TOP);
  ASSERT_NE(low.best(), nullptr);
  EXPECT_EQ(low.best()->kind, GraspKind::TOP);
}

TEST(GraspPlanner, TopGraspsComeStraightDownFromAbove) {
  const GraspPlan plan = plan_of(mug());
  int tops = 0;
  for (std::size_t i = 0; i < plan.feasible_count; ++i) {
    const Grasp& g = plan.feasible[i];
    if (g.kind != GraspKind::TOP) { continue; }
    ++tops;
    EXPECT_NEAR(g.approach.dot(-Vector3d::UnitZ()), 1.0, 1e-12);
    EXPECT_NEAR(g.pre_grasp.translation().z() - g.grasp.translation().z(), 0.15, 1e-12);
    // A 10 cm box: the fingers wrap its top 5 cm, the grasp centre at the box centre.
    EXPECT_NEAR(g.grasp.translation().z(), 0.05, 1e-12);
  }
  EXPECT_EQ(tops, 2) << "closing along either horizontal axis";
}

// Side grasps approach horizontally along a principal axis of the box, from the arm's side.
TEST(GraspPlanner, SideGraspsAreHorizontalAlongTheBoxAxesAndAwayFromTheArm) {
  for (const double yaw : {0.0, 30.0 * DEG, -70.0 * DEG}) {
    const ObjectBox box = mug(yaw);
    const GraspPlan plan = plan_of(box);
    int sides = 0;
    for (std::size_t i = 0; i < plan.feasible_count; ++i) {
      const Grasp& g = plan.feasible[i];
      if (g.kind != GraspKind::SIDE) { continue; }
      ++sides;
      EXPECT_NEAR(g.approach.z(), 0.0, 1e-12);
      const double along_x = std::abs(g.approach.dot(box.base_from_object.linear().col(0)));
      const double along_y = std::abs(g.approach.dot(box.base_from_object.linear().col(1)));
      EXPECT_NEAR(std::max(along_x, along_y), 1.0, 1e-9) << "yaw " << yaw / DEG;
      const Vector3d radial = Vector3d(0.30, -0.30, 0.0).normalized();
      EXPECT_GE(g.approach.dot(radial), 0.0);
      EXPECT_NEAR((g.grasp.translation() - box.base_from_object.translation()).norm(), 0.0, 1e-12)
          << "the hand closes at the box centre";
    }
    EXPECT_EQ(sides, 2) << "yaw " << yaw / DEG;
  }
}

// The orientation constraint: in every grasp the fingers close horizontally, so the object's up
// stays up; the carry pose changes the height only.
TEST(GraspPlanner, EveryGraspKeepsTheObjectParallelToTheTable) {
  const GraspPlan plan = plan_of(mug(20.0 * DEG));
  ASSERT_GT(plan.feasible_count, 0U);
  for (std::size_t i = 0; i < plan.feasible_count; ++i) {
    const Grasp& g = plan.feasible[i];
    EXPECT_NEAR(g.grasp.linear().col(1).z(), 0.0, 1e-12) << "closing axis horizontal";
    const Isometry3d lifted = carry_pose(g, SupportPlane{}, 0.12);
    EXPECT_TRUE(lifted.linear().isApprox(g.grasp.linear()));
    EXPECT_NEAR((lifted.translation() - g.grasp.translation() - Vector3d(0, 0, 0.12)).norm(), 0.0,
                1e-12);
  }
}

TEST(GraspPlanner, TheOpeningIsTheWidthPlusClearanceUpToTheHandsLimit) {
  const GraspPlan narrow = plan_of(box_at({0.30, -0.30, 0.05}, {0.06, 0.06, 0.10}));
  ASSERT_NE(narrow.best(), nullptr);
  EXPECT_NEAR(narrow.best()->width_m, 0.06, 1e-12);
  EXPECT_NEAR(narrow.best()->opening_m, 0.08, 1e-12);
  // 13 cm across: the hand opens fully (14 cm), keeping 1 cm of margin.
  const GraspPlan wide = plan_of(box_at({0.30, -0.30, 0.05}, {0.13, 0.13, 0.10}));
  ASSERT_NE(wide.best(), nullptr);
  EXPECT_NEAR(wide.best()->opening_m, 0.14, 1e-12);
}

TEST(GraspPlanner, ABoxWiderThanTheHandHasNoCandidate) {
  const GraspPlan plan = plan_of(box_at({0.30, -0.30, 0.05}, {0.20, 0.20, 0.10}));
  EXPECT_EQ(plan.feasible_count, 0U);
  EXPECT_EQ(plan.best(), nullptr);
  ASSERT_GT(plan.rejected_count, 0U);
  for (std::size_t i = 0; i < plan.rejected_count; ++i) {
    EXPECT_EQ(plan.rejected[i].reason, GraspRejection::TOO_WIDE);
  }
  // A 20 x 6 cm box is grasped across its narrow side only.
  const GraspPlan long_box = plan_of(box_at({0.30, -0.30, 0.05}, {0.20, 0.06, 0.10}));
  ASSERT_GT(long_box.feasible_count, 0U);
  for (std::size_t i = 0; i < long_box.feasible_count; ++i) {
    EXPECT_NEAR(long_box.feasible[i].width_m, 0.06, 1e-12);
  }
  EXPECT_TRUE(has_rejection(long_box, GraspRejection::TOO_WIDE));
}

TEST(GraspPlanner, AThinObjectIsRefusedAsTooThin) {
  const GraspPlan plan = plan_of(box_at({0.30, -0.30, 0.10}, {0.005, 0.005, 0.20}));
  EXPECT_EQ(plan.feasible_count, 0U);
  EXPECT_TRUE(has_rejection(plan, GraspRejection::TOO_THIN));
}

// A 1.5 cm tall box: the fingertips would touch the table before the pads cover the box.
TEST(GraspPlanner, AFlatObjectHitsTheTable) {
  const GraspPlan plan = plan_of(box_at({0.30, -0.30, 0.0075}, {0.08, 0.08, 0.015}));
  EXPECT_EQ(plan.feasible_count, 0U);
  EXPECT_TRUE(has_rejection(plan, GraspRejection::HITS_TABLE));
}

TEST(GraspPlanner, APoseTheArmCannotReachIsRejectedWithTheReason) {
  // Within the reach sphere but behind the arm's comfortable workspace.
  const GraspPlan plan = plan_of(box_at({0.60, -0.60, 0.05}, {0.07, 0.07, 0.10}));
  EXPECT_EQ(plan.feasible_count, 0U);
  EXPECT_TRUE(has_rejection(plan, GraspRejection::UNREACHABLE_PRE_GRASP) ||
              has_rejection(plan, GraspRejection::UNREACHABLE_GRASP));
}

TEST(GraspPlanner, TheJointSolutionsReachThePoses) {
  const GraspPlan plan = plan_of(mug(15.0 * DEG));
  ASSERT_GT(plan.feasible_count, 0U);
  const auto limits = drivers::jaco::jaco_joint_limits();
  for (std::size_t i = 0; i < plan.feasible_count; ++i) {
    const Grasp& g = plan.feasible[i];
    for (const auto& [joints, pose] :
         {std::pair{g.pre_grasp_joints, g.pre_grasp}, std::pair{g.grasp_joints, g.grasp}}) {
      EXPECT_TRUE(limits.contains(joints));
      const Isometry3d reached = drivers::jaco::forward_kinematics(joints);
      EXPECT_LT((reached.translation() - pose.translation()).norm(), 1e-4);
      EXPECT_LT(Eigen::AngleAxisd(reached.linear().transpose() * pose.linear()).angle(), 1e-3);
    }
  }
  for (std::size_t i = 1; i < plan.feasible_count; ++i) {
    if (plan.feasible[i].kind == plan.feasible[i - 1].kind) {
      EXPECT_LE(plan.feasible[i - 1].joint_travel_deg, plan.feasible[i].joint_travel_deg);
    }
  }
}

TEST(GraspPlanner, ATiltedTableIsHonoured) {
  // The table tilted 10 degrees about x, the box resting on it.
  GraspOptions options;
  const Eigen::Matrix3d tilt = AngleAxisd(10.0 * DEG, Vector3d::UnitX()).toRotationMatrix();
  options.table.normal = tilt * Vector3d::UnitZ();
  options.table.offset = 0.0;
  ObjectBox box = mug();
  box.base_from_object.linear() = tilt;
  box.base_from_object.translation() = Vector3d(0.30, -0.30, 0.0) + 0.05 * options.table.normal;
  const GraspPlan plan = plan_of(box, options);
  ASSERT_GT(plan.feasible_count, 0U);
  for (std::size_t i = 0; i < plan.feasible_count; ++i) {
    const Grasp& g = plan.feasible[i];
    EXPECT_NEAR(g.approach.dot(options.table.normal), g.kind == GraspKind::TOP ? -1.0 : 0.0, 1e-9);
  }
}

TEST(GraspPlanner, RefusesANonFiniteBoxOrTable) {
  ObjectBox box = mug();
  box.base_from_object.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(plan_grasp(box, {}).error(), ObjectRejection::NOT_FINITE);
  ObjectBox size = mug();
  size.extents.y() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(plan_grasp(size, {}).error(), ObjectRejection::NOT_FINITE);
  GraspOptions options;
  options.table.normal = Vector3d::Zero();
  EXPECT_EQ(plan_grasp(mug(), options).error(), ObjectRejection::NOT_FINITE);
  GraspOptions seed;
  seed.seed[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(plan_grasp(mug(), seed).error(), ObjectRejection::NOT_FINITE);
}

TEST(GraspPlanner, RefusesAFrameThatIsNotARotation) {
  ObjectBox scaled = mug();
  scaled.base_from_object.linear() *= 1.1;
  EXPECT_EQ(plan_grasp(scaled, {}).error(), ObjectRejection::NOT_RIGID);
  ObjectBox mirrored = mug();
  mirrored.base_from_object.linear().col(2) *= -1.0;
  EXPECT_EQ(plan_grasp(mirrored, {}).error(), ObjectRejection::NOT_RIGID);
}

TEST(GraspPlanner, RefusesBadExtents) {
  EXPECT_EQ(plan_grasp(box_at({0.3, -0.3, 0.05}, {0.08, -0.01, 0.1}), {}).error(),
            ObjectRejection::BAD_EXTENTS);
  EXPECT_EQ(plan_grasp(box_at({0.3, -0.3, 0.05}, {0.0, 0.0, 0.0}), {}).error(),
            ObjectRejection::BAD_EXTENTS);
}

TEST(GraspPlanner, RefusesABoxInsideTheTable) {
  EXPECT_EQ(plan_grasp(box_at({0.3, -0.3, -0.02}, {0.08, 0.08, 0.10}), {}).error(),
            ObjectRejection::INSIDE_TABLE);
  // Resting 1 cm low (segmentation noise) is still planned.
  EXPECT_TRUE(plan_grasp(box_at({0.3, -0.3, 0.04}, {0.08, 0.08, 0.10}), {}).has_value());
}

TEST(GraspPlanner, RefusesABoxBeyondTheArmsReach) {
  EXPECT_EQ(plan_grasp(box_at({1.2, 0.0, 0.05}, {0.08, 0.08, 0.10}), {}).error(),
            ObjectRejection::OUT_OF_REACH);
}

TEST(GraspPlanner, EveryReasonHasAMessage) {
  for (const auto r :
       {GraspRejection::TOO_WIDE, GraspRejection::TOO_THIN, GraspRejection::HITS_TABLE,
        GraspRejection::UNREACHABLE_PRE_GRASP, GraspRejection::UNREACHABLE_GRASP}) {
    EXPECT_GT(std::string(to_string(r)).size(), 8U);
  }
  for (const auto r :
       {ObjectRejection::NOT_FINITE, ObjectRejection::NOT_RIGID, ObjectRejection::BAD_EXTENTS,
        ObjectRejection::INSIDE_TABLE, ObjectRejection::OUT_OF_REACH}) {
    EXPECT_GT(std::string(to_string(r)).size(), 8U);
  }
}

// A GOOD frame (world -> object, row-major) of an object seen by a camera: the box lands where the
// object is in the base frame, and a reflected frame becomes a proper rotation.
TEST(GraspPlanner, TheBoxOfAGoodFrameIsTheObjectInTheBaseFrame) {
  Isometry3d base_from_camera = Isometry3d::Identity();
  base_from_camera.linear() = AngleAxisd(-2.2, Vector3d::UnitX()).toRotationMatrix();
  base_from_camera.translation() = Vector3d(0.2, -1.0, 0.7);
  const Vector3d centre_in_base(0.3, -0.3, 0.05);
  Isometry3d camera_from_object = Isometry3d::Identity();
  camera_from_object.linear() =
      base_from_camera.linear().transpose() * AngleAxisd(0.3, Vector3d::UnitZ()).toRotationMatrix();
  camera_from_object.translation() = base_from_camera.inverse() * centre_in_base;
  const Isometry3d object_from_camera = camera_from_object.inverse();
  std::array<float, 16> frame{};
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      frame[static_cast<std::size_t>(4 * r + c)] =
          static_cast<float>(object_from_camera.matrix()(r, c));
    }
  }
  const ObjectBox box = object_box_in_base(base_from_camera, frame, {0.08F, 0.07F, 0.1F});
  EXPECT_LT((box.base_from_object.translation() - centre_in_base).norm(), 1e-6);
  EXPECT_NEAR(box.base_from_object.linear().col(2).z(), 1.0, 1e-6);
  EXPECT_NEAR(box.extents.y(), 0.07, 1e-7);
  // The same frame with its third row negated (a reflection): still a proper box.
  for (int c = 0; c < 4; ++c) { frame[static_cast<std::size_t>(8 + c)] *= -1.0F; }
  const ObjectBox mirrored = object_box_in_base(base_from_camera, frame, {0.08F, 0.07F, 0.1F});
  EXPECT_GT(mirrored.base_from_object.linear().determinant(), 0.0);
  EXPECT_TRUE(plan_grasp(mirrored, {}).has_value());
}

}  // namespace
}  // namespace orthoflow::manipulation
