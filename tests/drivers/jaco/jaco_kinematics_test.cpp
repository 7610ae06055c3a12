// JACO kinematics: FK against Kinova's published numbers (docs/JACO_KINEMATICS_SOURCES.md), the
// Euler convention, and the IK: random round trips, every IkError, limits, turns, no heap,
// determinism.
#include "drivers/jaco/jaco_kinematics.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>

#if defined(__GNUC__) && !defined(__clang__)  // GCC flags the replacement delete's (correct) free()
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
#include "tests/support/counting_new.hpp"  // the one TU of this binary that replaces operator new

namespace orthoflow::drivers::jaco {
namespace {

constexpr double PI = std::numbers::pi;
constexpr double DEG = PI / 180.0;

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle();
}

// A configuration drawn uniformly within the limits (continuous joints over their whole bounds).
JointAngles random_within(std::mt19937& rng, const JointLimits& limits) {
  JointAngles q{};
  for (std::size_t i = 0; i < 6; ++i) {
    q[i] = std::uniform_real_distribution<double>(limits.lower[i], limits.upper[i])(rng);
  }
  return q;
}

// Kinova's j2n6s300 URDF (kinova-ros kinova_description/urdf/j2n6s300.xacro), an independent model:
// per joint an origin (xyz, rpy), then z by the actuator angle; then the end-effector joint.
Eigen::Isometry3d urdf_fk(const JointAngles& q_deg) {
  using Origin = std::array<double, 6>;  // x, y, z, roll, pitch, yaw
  constexpr std::array<Origin, 7> ORIGINS = {{{0, 0, 0.15675, 0, PI, 0},
                                              {0, 0.0016, -0.11875, -PI / 2, 0, PI},
                                              {0, -0.410, 0, 0, PI, 0},
                                              {0, 0.2073, -0.0114, -PI / 2, 0, PI},
                                              {0, -0.03703, -0.06414, PI / 3, 0, PI},
                                              {0, -0.03703, -0.06414, PI / 3, 0, PI},
                                              {0, 0, -0.1600, PI, 0, PI / 2}}};
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < ORIGINS.size(); ++i) {
    const Origin& o = ORIGINS[i];
    t.translate(Eigen::Vector3d(o[0], o[1], o[2]));
    t.rotate(Eigen::AngleAxisd(o[5], Eigen::Vector3d::UnitZ()) *
             Eigen::AngleAxisd(o[4], Eigen::Vector3d::UnitY()) *
             Eigen::AngleAxisd(o[3], Eigen::Vector3d::UnitX()));
    if (i < 6) t.rotate(Eigen::AngleAxisd(q_deg[i] * DEG, Eigen::Vector3d::UnitZ()));
  }
  return t;
}

TEST(JacoKinematics, HomeMatchesKinovasDocumentedHomePose) {
  // j2n6s300.srdf's "Home" (radians, URDF = actuator angles) and pose_action_client.py's "default
  // home" tool pose (m, Euler XYZ rad): roundings of one pose, 2.8 mm and 0.42 degrees apart.
  const JointAngles home = {4.8046852 / DEG, 2.92482 / DEG, 1.002 / DEG,
                            4.2031852 / DEG, 1.4458 / DEG,  1.3233 / DEG};
  CartesianPose documented;
  documented.position = {0.212322831154, -0.257197618484, 0.509646713734};
  documented.theta = {1.63771402836, 1.11316478252, 0.134094119072};
  const Eigen::Isometry3d fk = forward_kinematics(home);
  const Eigen::Isometry3d expected = to_transform(documented);
  EXPECT_LT((fk.translation() - expected.translation()).norm(), 0.0035);
  EXPECT_LT(angle_between(fk.linear(), expected.linear()), 0.6 * DEG);
  std::printf("home: %.2f mm, %.2f deg from the documented pose\n",
              1e3 * (fk.translation() - expected.translation()).norm(),
              angle_between(fk.linear(), expected.linear()) / DEG);
}

// The chain's frames: the base first, the tool last, equal to forward_kinematics on both models;
// the shoulder sits D1 = 0.2755 m above the base.
TEST(JacoKinematics, ChainFramesEndAtTheToolPose) {
  const JointAngles q{250.0, 200.0, 80.0, 200.0, 100.0, 30.0};
  for (const ArmGeometry* g : {&jaco2_geometry(), &jaco_v1_geometry()}) {
    const ChainFrames f = forward_kinematics_frames(q, *g);
    EXPECT_TRUE(f[0].isApprox(Eigen::Isometry3d::Identity()));
    EXPECT_LT((f[6].matrix() - forward_kinematics(q, *g).matrix()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_NEAR(f[1].translation().z(), 0.2755, 1e-12);
    EXPECT_NEAR(f[1].translation().head<2>().norm(), 0.0, 1e-12);
    EXPECT_NEAR((f[2].translation() - f[1].translation()).norm(), 0.41, 1e-12) << "the upper arm";
  }
}

TEST(JacoKinematics, Jaco2MatchesKinovasUrdf) {
  std::mt19937 rng(7);
  double worst_m = 0.0, worst_rad = 0.0;
  for (int n = 0; n < 500; ++n) {
    const JointAngles q = random_within(rng, jaco_joint_limits());
    const Eigen::Isometry3d dh = forward_kinematics(q), urdf = urdf_fk(q);
    worst_m = std::max(worst_m, (dh.translation() - urdf.translation()).norm());
    worst_rad = std::max(worst_rad, angle_between(dh.linear(), urdf.linear()));
  }
  // The URDF rounds the wrist offsets to 0.01 mm (0.03703, 0.06414 for 0.0741 at 30 degrees).
  EXPECT_LT(worst_m, 1e-4);
  EXPECT_LT(worst_rad, 1e-9);
  std::printf("urdf: worst %.3g mm, %.3g rad\n", worst_m * 1e3, worst_rad);
}

TEST(JacoKinematics, V1MatchesTheKnownAnswersOfKinovasTable) {
  // Computed from Kinova's "DH Parameters of Jaco" (1.1.x) table: the reset pose, all actuators at
  // 180 degrees, and the DH zero (q = -theta1, theta2 + 90, theta3 - 90, theta4, theta5 + 180,
  // theta6 - 100 at theta = 0).
  const Eigen::Vector3d reset =
      forward_kinematics({180, 180, 180, 180, 180, 180}, jaco_v1_geometry()).translation();
  EXPECT_LT((reset - Eigen::Vector3d(0.0, 0.276298, 0.910704)).norm(), 1e-6);
  const Eigen::Vector3d zero =
      forward_kinematics({0, 90, -90, 0, 180, -100}, jaco_v1_geometry()).translation();
  EXPECT_LT((zero - Eigen::Vector3d(0.41, 0.256698, 0.050296)).norm(), 1e-6);
}

TEST(JacoKinematics, ModelsShareTheArmAndDifferInTheWrist) {
  for (std::size_t i = 0; i < 3; ++i) {  // D1, D2, D3, e2 and the offsets of joints 1 to 3
    EXPECT_EQ(jaco2_geometry().rows[i].d_m, jaco_v1_geometry().rows[i].d_m);
    EXPECT_EQ(jaco2_geometry().rows[i].a_m, jaco_v1_geometry().rows[i].a_m);
    EXPECT_EQ(jaco2_geometry().rows[i].offset_rad, jaco_v1_geometry().rows[i].offset_rad);
  }
  EXPECT_NEAR(jaco_v1_geometry().rows[5].offset_rad - jaco2_geometry().rows[5].offset_rad, 10 * DEG,
              1e-12);  // joint 6: 260 versus 270 degrees in kinova-ros' old offsets
}

TEST(JacoKinematics, EulerConventionIsRxRyRz) {
  // kinova-ros EulerXYZ2Matrix3x3, element by element.
  const double tx = 0.3, ty = -0.7, tz = 1.9;
  const double sx = std::sin(tx), cx = std::cos(tx), sy = std::sin(ty), cy = std::cos(ty);
  const double sz = std::sin(tz), cz = std::cos(tz);
  Eigen::Matrix3d expected;
  expected << cz * cy, -sz * cy, sy, cz * sy * sx + sz * cx, -sz * sy * sx + cz * cx, -cy * sx,
      -cz * sy * cx + sz * sx, sz * sy * cx + cz * sx, cy * cx;
  CartesianPose pose;
  pose.theta = {tx, ty, tz};
  EXPECT_LT((to_transform(pose).linear() - expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(JacoKinematics, PoseRoundTripsIncludingGimbalLock) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> turn(-PI, PI), half(-PI / 2, PI / 2);
  for (int n = 0; n < 1000; ++n) {
    CartesianPose pose;
    pose.position = {turn(rng), turn(rng), turn(rng)};
    pose.theta = {turn(rng), half(rng), turn(rng)};
    const CartesianPose back = to_pose(to_transform(pose));
    EXPECT_LT((back.theta - pose.theta).norm(), 1e-9) << n;
    EXPECT_EQ(back.position, pose.position);
  }
  for (double lock : {PI / 2, -PI / 2}) {
    for (double off : {0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-6, -1e-6, 1e-3}) {
      CartesianPose pose;
      pose.theta = {0.4, lock + off, -1.1};
      const Eigen::Isometry3d t = to_transform(pose);
      const CartesianPose back = to_pose(t);
      EXPECT_LE(std::abs(back.theta.y()), PI / 2);
      EXPECT_LT((to_transform(back).linear() - t.linear()).cwiseAbs().maxCoeff(), 1e-14) << off;
    }
  }
  EXPECT_EQ(to_pose(to_transform({{}, {0.4, PI / 2, -1.1}})).theta.x(), 0.0);  // locked: x is 0
}

void expect_round_trips(const ArmGeometry& geometry, const char* name) {
  const JointLimits limits = jaco_joint_limits();
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> perturb(-20.0, 20.0);
  double worst_m = 0.0, worst_rad = 0.0;
  const int count = 1000;
  for (int n = 0; n < count; ++n) {
    JointAngles q = random_within(rng, limits);
    for (std::size_t i = 0; i < 6 && n % 4 == 0; ++i) {  // near the continuous bounds: turns wrap
      if (i != 1 && i != 2) q[i] = CONTINUOUS_BOUND_DEG - std::fmod(std::abs(q[i]), 360.0);
    }
    JointAngles seed = q;
    for (double& v : seed) v += perturb(rng);
    const Eigen::Isometry3d target = forward_kinematics(q, geometry);
    const auto solution_result = inverse_kinematics(target, seed, limits, {}, geometry);
    ASSERT_TRUE(solution_result.has_value()) << name << " configuration " << n;
    EXPECT_TRUE(limits.contains(*solution_result)) << n;
    const Eigen::Isometry3d reached = forward_kinematics(*solution_result, geometry);
    worst_m = std::max(worst_m, (reached.translation() - target.translation()).norm());
    worst_rad = std::max(worst_rad, angle_between(reached.linear(), target.linear()));
  }
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_LT(worst_rad, 0.5 * DEG);
  std::printf("%s: %d/%d round trips, worst %.3g mm, %.3g deg\n", name, count, count, worst_m * 1e3,
              worst_rad / DEG);
}

TEST(JacoKinematics, IkRoundTripsFromPerturbedSeedsJaco2) {
  expect_round_trips(jaco2_geometry(), "jaco2");
}

TEST(JacoKinematics, IkRoundTripsFromPerturbedSeedsV1) {
  expect_round_trips(jaco_v1_geometry(), "jaco_v1");
}

TEST(JacoKinematics, IkFromTheExactSolutionReturnsTheSeed) {
  std::mt19937 rng(5);
  for (int n = 0; n < 200; ++n) {
    const JointAngles q = random_within(rng, jaco_joint_limits());
    const auto solution_result = inverse_kinematics(forward_kinematics(q), q, jaco_joint_limits());
    ASSERT_TRUE(solution_result.has_value());
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR((*solution_result)[i], q[i], 1e-9) << n;
  }
}

TEST(JacoKinematics, ContinuousJointsComeBackInTheSeedsTurn) {
  const JointAngles q = {275, 167, 57, 240, 83, 75};
  const JointAngles seed = {275 + 720 + 5, 160, 60, 240 - 1080 - 5, 83 + 360, 75 - 3};
  const auto solution_result = inverse_kinematics(forward_kinematics(q), seed, jaco_joint_limits());
  ASSERT_TRUE(solution_result.has_value());
  for (std::size_t i = 0; i < 6; ++i) EXPECT_LT(std::abs((*solution_result)[i] - seed[i]), 10.0);
  EXPECT_NEAR((*solution_result)[0], 275 + 720, 1e-2);
  JointLimits one_turn = jaco_joint_limits();  // joint 4 continuous over exactly [0, 360]
  one_turn.lower[3] = 0.0;
  one_turn.upper[3] = 360.0;
  const auto wrapped_result = inverse_kinematics(forward_kinematics({275, 167, 57, 10, 83, 75}),
                                                 {275, 167, 57, 350, 83, 75}, one_turn);
  ASSERT_TRUE(wrapped_result.has_value());  // 370, nearest the seed, is turned back inside: 10
  EXPECT_NEAR((*wrapped_result)[3], 10.0, 1e-2);
}

TEST(JacoKinematics, UnreachableTargetsAreRefused) {
  const JointAngles home = {275, 167, 57, 240, 83, 75};
  Eigen::Isometry3d target = forward_kinematics(home);
  target.translation() = Eigen::Vector3d(2.0, 0.0, 0.3);  // beyond any reach: refused at once
  EXPECT_EQ(inverse_kinematics(target, home, jaco_joint_limits()).error(), IkError::UNREACHABLE);
  // Inside the sphere of the summed link lengths, beyond the stretched arm: every start fails.
  target.translation() = Eigen::Vector3d(0.0, -0.93, 0.2755);
  EXPECT_EQ(inverse_kinematics(target, home, jaco_joint_limits()).error(), IkError::UNREACHABLE);
}

TEST(JacoKinematics, LimitsAreRespected) {
  // Joint 2 confined above the configuration's own angle: any answer must keep to the limit.
  const JointAngles q = {10, 120, 200, 30, 70, 40};
  JointLimits limits = jaco_joint_limits();
  limits.lower[1] = 150.0;
  const auto result = inverse_kinematics(forward_kinematics(q), q, limits);
  EXPECT_TRUE(result.has_value() ? limits.contains(*result)
                                 : result.error() == IkError::UNREACHABLE);
  // Joint 1 confined to a degree that cannot face the target: refused.
  limits = jaco_joint_limits();
  limits.lower[0] = 100.0;
  limits.upper[0] = 101.0;
  EXPECT_EQ(inverse_kinematics(forward_kinematics(q), q, limits).error(), IkError::UNREACHABLE);
}

TEST(JacoKinematics, NonFiniteInputsAreRefused) {
  const JointAngles home = {275, 167, 57, 240, 83, 75};
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = HUGE_VAL;
  Eigen::Isometry3d target = forward_kinematics(home);
  target.translation().x() = nan;
  EXPECT_EQ(inverse_kinematics(target, home, jaco_joint_limits()).error(), IkError::NOT_FINITE);
  target = forward_kinematics(home);
  target.linear()(1, 2) = inf;
  EXPECT_EQ(inverse_kinematics(target, home, jaco_joint_limits()).error(), IkError::NOT_FINITE);
  JointAngles seed = home;
  seed[3] = nan;
  EXPECT_EQ(inverse_kinematics(forward_kinematics(home), seed, jaco_joint_limits()).error(),
            IkError::NOT_FINITE);
  EXPECT_STREQ(to_string(IkError::NOT_FINITE), "not_finite");
  EXPECT_STREQ(to_string(IkError::UNREACHABLE), "unreachable");
}

TEST(JacoKinematics, JointLimitsContain) {
  const JointLimits limits = jaco_joint_limits();  // inclusive; NaN is outside
  EXPECT_TRUE(limits.contains({0, 47, 341, 0, 0, 0}));
  EXPECT_FALSE(limits.contains({0, 46.9, 180, 0, 0, 0}));
  EXPECT_FALSE(limits.contains({0, 180, 341.1, 0, 0, 0}));
  EXPECT_FALSE(limits.contains({std::numeric_limits<double>::quiet_NaN(), 180, 180, 0, 0, 0}));
}

TEST(JacoKinematics, NeverAllocates) {
  const JointAngles home = {275, 167, 57, 240, 83, 75};
  Eigen::Isometry3d far = forward_kinematics(home);
  far.translation() = Eigen::Vector3d(0.0, -0.93, 0.2755);  // every restart runs
  test::g_allocations = 0;
  test::g_counting = true;
  const Eigen::Isometry3d target = forward_kinematics({270, 180, 60, 230, 90, 80});
  const auto near_result = inverse_kinematics(target, home, jaco_joint_limits());
  const auto far_result = inverse_kinematics(far, home, jaco_joint_limits());
  test::g_counting = false;
  EXPECT_EQ(test::g_allocations.load(), 0U);
  EXPECT_TRUE(near_result.has_value());
  EXPECT_FALSE(far_result.has_value());
}

TEST(JacoKinematics, IkIsDeterministic) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> perturb(-40.0, 40.0);
  for (int n = 0; n < 50; ++n) {
    const JointAngles q = random_within(rng, jaco_joint_limits());
    JointAngles seed = q;
    for (double& v : seed) v += perturb(rng);
    const Eigen::Isometry3d target = forward_kinematics(q);
    const auto first = inverse_kinematics(target, seed, jaco_joint_limits());
    const auto second = inverse_kinematics(target, seed, jaco_joint_limits());
    ASSERT_EQ(first.has_value(), second.has_value());
    if (first.has_value()) {
      EXPECT_EQ(std::memcmp(first->data(), second->data(), sizeof(JointAngles)), 0) << n;
    }
  }
}

}  // namespace
}  // namespace orthoflow::drivers::jaco
