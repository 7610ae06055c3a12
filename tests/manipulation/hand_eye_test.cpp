// Eye-to-hand calibration (manipulation/hand_eye.hpp): a known camera pose is recovered from arm
// poses of the JACO's forward kinematics and simulated noisy observations of a held target, within
// the 2 mm and 0.5 degrees; every refusal is triggered.
#include "manipulation/hand_eye.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/jaco/jaco_kinematics.hpp"

namespace orthoflow::manipulation {
namespace {

using Eigen::AngleAxisd;
using Eigen::Isometry3d;
using Eigen::Vector3d;

constexpr double DEG = std::numbers::pi / 180.0;

// The camera 1 m in front of the arm and 0.7 m up, looking back and down at the table.
Isometry3d true_base_from_camera() {
  Isometry3d x = Isometry3d::Identity();
  x.linear() =
      (AngleAxisd(0.4, Vector3d::UnitZ()) * AngleAxisd(-2.3, Vector3d::UnitX())).toRotationMatrix();
  x.translation() = Vector3d(0.25, -1.0, 0.7);
  return x;
}
// A marker 6 cm beyond the tool point, tilted.
Isometry3d true_gripper_from_target() {
  Isometry3d y = Isometry3d::Identity();
  y.linear() = AngleAxisd(20.0 * DEG, Vector3d(1.0, 0.3, 0.0).normalized()).toRotationMatrix();
  y.translation() = Vector3d(0.01, -0.02, 0.06);
  return y;
}

struct Noise {
  double arm_position_m = 0.0005;  // the arm's repeatability
  double arm_rotation_rad = 0.05 * DEG;
  double camera_position_m = 0.0015;  // a Kinect's target position at about 1 m
  double camera_rotation_rad = 0.3 * DEG;
};

Isometry3d jitter(const Isometry3d& t, double position_m, double rotation_rad,
                  std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Isometry3d out = t;
  const Vector3d w(n(rng), n(rng), n(rng));
  out.linear() =
      t.linear() * AngleAxisd(rotation_rad * w.norm(), w.normalized()).toRotationMatrix();
  out.translation() += position_m * Vector3d(n(rng), n(rng), n(rng));
  return out;
}

// Arm poses around HOME: every joint within +-45 degrees, as a person would jog the arm around the
// workspace while the camera keeps the target in view.
std::vector<Isometry3d> arm_poses(std::size_t count, std::mt19937_64& rng) {
  const drivers::jaco::JointAngles home = drivers::jaco::HOME_JOINTS;
  std::uniform_real_distribution<double> u(-45.0, 45.0);
  std::vector<Isometry3d> poses;
  for (std::size_t i = 0; i < count; ++i) {
    drivers::jaco::JointAngles q = home;
    for (double& a : q) { a += u(rng); }
    poses.push_back(drivers::jaco::forward_kinematics(q));
  }
  return poses;
}

std::vector<PoseSample> pose_samples(std::size_t count, std::uint64_t seed, const Noise& noise) {
  std::mt19937_64 rng(seed);
  const Isometry3d x = true_base_from_camera();
  const Isometry3d y = true_gripper_from_target();
  std::vector<PoseSample> samples;
  for (const Isometry3d& a : arm_poses(count, rng)) {
    const Isometry3d b = x.inverse() * a * y;
    samples.push_back({jitter(a, noise.arm_position_m, noise.arm_rotation_rad, rng),
                       jitter(b, noise.camera_position_m, noise.camera_rotation_rad, rng)});
  }
  return samples;
}

std::vector<PointSample> point_samples(std::size_t count, std::uint64_t seed, const Noise& noise) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  const Isometry3d x = true_base_from_camera();
  const Vector3d p = true_gripper_from_target().translation();
  std::vector<PointSample> samples;
  for (const Isometry3d& a : arm_poses(count, rng)) {
    const Vector3d c = x.inverse() * (a * p);
    samples.push_back({jitter(a, noise.arm_position_m, noise.arm_rotation_rad, rng),
                       c + noise.camera_position_m * Vector3d(n(rng), n(rng), n(rng))});
  }
  return samples;
}

double position_error(const HandEyeResult& r) {
  return (r.base_from_camera.translation() - true_base_from_camera().translation()).norm();
}
double rotation_error(const HandEyeResult& r) {
  return rotation_angle_between(r.base_from_camera.linear(), true_base_from_camera().linear());
}

TEST(HandEye, PoseSamplesWithoutNoiseGiveTheTransformExactly) {
  const auto samples = pose_samples(12, 1, Noise{0.0, 0.0, 0.0, 0.0});
  const auto r = solve_hand_eye(std::span<const PoseSample>(samples));
  ASSERT_TRUE(r.has_value()) << to_string(r.error());
  EXPECT_LT(position_error(r.value()), 1e-9);
  EXPECT_LT(rotation_error(r.value()), 1e-9);
  EXPECT_LT((r.value().gripper_from_target.matrix() - true_gripper_from_target().matrix()).norm(),
            1e-8);
  EXPECT_LT(r.value().rms_position_m, 1e-9);
}

TEST(HandEye, PointSamplesWithoutNoiseGiveTheTransformExactly) {
  const auto samples = point_samples(12, 2, Noise{0.0, 0.0, 0.0, 0.0});
  const auto r = solve_hand_eye(std::span<const PointSample>(samples));
  ASSERT_TRUE(r.has_value()) << to_string(r.error());
  EXPECT_LT(position_error(r.value()), 1e-9);
  EXPECT_LT(rotation_error(r.value()), 1e-9);
  EXPECT_LT((r.value().gripper_from_target.translation() - true_gripper_from_target().translation())
                .norm(),
            1e-9);
}

// The bar: within 2 mm and 0.5 degrees from simulated noisy observations, on ten seeds.
// The conditions: 50 arm poses; the arm's readings off by 0.5 mm and 0.05 degrees (its
// repeatability); the target's pose in the camera off by 1 mm and 0.2 degrees per axis (a marker
// seen by an RGB-D camera at about 1 m). The camera's position error is mostly its rotation error
// times the 1.2 m from the camera to the workspace, so fewer poses or noisier observations miss
// 2 mm (30 poses at 1.5 mm: up to 2.5 mm, docs/MANIPULATION.md).
TEST(HandEye, NoisyPoseSamplesRecoverTheCameraWithin2mmAndHalfADegree) {
  double worst_position = 0.0, worst_rotation = 0.0;
  for (std::uint64_t seed = 10; seed < 20; ++seed) {
    const auto samples = pose_samples(50, seed, Noise{0.0005, 0.05 * DEG, 0.001, 0.2 * DEG});
    const auto r = solve_hand_eye(std::span<const PoseSample>(samples));
    ASSERT_TRUE(r.has_value()) << to_string(r.error());
    worst_position = std::max(worst_position, position_error(r.value()));
    worst_rotation = std::max(worst_rotation, rotation_error(r.value()));
    // The residual reflects the noise put in (about 1.8 mm of position per sample).
    EXPECT_GT(r.value().rms_position_m, 0.0008);
    EXPECT_LT(r.value().rms_position_m, 0.004);
  }
  EXPECT_LT(worst_position, 0.002);
  EXPECT_LT(worst_rotation, 0.5 * DEG);
  std::printf("pose samples, 50 per solve, 10 seeds: worst %.3f mm, %.3f deg\n",
              worst_position * 1e3, worst_rotation / DEG);
}

// A ball's centre carries half the information of a pose: 60 poses, the centre off by 1 mm per
// axis (a sphere fitted to a few hundred depth points).
TEST(HandEye, NoisyPointSamplesRecoverTheCameraWithin2mmAndHalfADegree) {
  double worst_position = 0.0, worst_rotation = 0.0;
  for (std::uint64_t seed = 30; seed < 40; ++seed) {
    const auto samples = point_samples(60, seed, Noise{0.0005, 0.05 * DEG, 0.001, 0.0});
    const auto r = solve_hand_eye(std::span<const PointSample>(samples));
    ASSERT_TRUE(r.has_value()) << to_string(r.error());
    worst_position = std::max(worst_position, position_error(r.value()));
    worst_rotation = std::max(worst_rotation, rotation_error(r.value()));
  }
  EXPECT_LT(worst_position, 0.002);
  EXPECT_LT(worst_rotation, 0.5 * DEG);
  std::printf("point samples, 60 per solve, 10 seeds: worst %.3f mm, %.3f deg\n",
              worst_position * 1e3, worst_rotation / DEG);
}

// One gross outlier among 30 is visible in the residuals (max far above rms): the command prints
// both, so a bad sample is found rather than averaged in silently.
TEST(HandEye, AnOutlierShowsInTheWorstResidual) {
  auto samples = pose_samples(30, 5, Noise{});
  samples[7].camera_from_target.translation() += Vector3d(0.05, 0.0, 0.0);
  const auto r = solve_hand_eye(std::span<const PoseSample>(samples));
  ASSERT_TRUE(r.has_value());
  EXPECT_GT(r.value().max_position_m, 3.0 * r.value().rms_position_m);
  EXPECT_EQ(r.value().worst_sample, 7U);
}

TEST(HandEye, RefusesTooFewSamples) {
  const auto poses = pose_samples(2, 1, Noise{});
  const auto points = point_samples(4, 1, Noise{});
  EXPECT_EQ(solve_hand_eye(std::span<const PoseSample>(poses)).error(),
            HandEyeError::TOO_FEW_SAMPLES);
  EXPECT_EQ(solve_hand_eye(std::span<const PointSample>(points)).error(),
            HandEyeError::TOO_FEW_SAMPLES);
}

TEST(HandEye, RefusesTooManySamples) {
  const std::vector<PointSample> points(HAND_EYE_MAX_SAMPLES + 1);
  EXPECT_EQ(solve_hand_eye(std::span<const PointSample>(points)).error(),
            HandEyeError::TOO_MANY_SAMPLES);
}

TEST(HandEye, RefusesNonFiniteSamples) {
  auto poses = pose_samples(10, 1, Noise{});
  poses[3].camera_from_target.translation().y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(solve_hand_eye(std::span<const PoseSample>(poses)).error(), HandEyeError::NOT_FINITE);
  auto points = point_samples(10, 1, Noise{});
  points[9].target_in_camera.z() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(solve_hand_eye(std::span<const PointSample>(points)).error(), HandEyeError::NOT_FINITE);
}

TEST(HandEye, RefusesRotationsThatAreNotRotations) {
  auto poses = pose_samples(10, 1, Noise{});
  poses[2].base_from_gripper.linear() *= 1.01;  // a scale
  EXPECT_EQ(solve_hand_eye(std::span<const PoseSample>(poses)).error(), HandEyeError::NOT_RIGID);
  auto mirrored = pose_samples(10, 1, Noise{});
  mirrored[4].camera_from_target.linear().col(0) *= -1.0;  // a reflection
  EXPECT_EQ(solve_hand_eye(std::span<const PoseSample>(mirrored)).error(), HandEyeError::NOT_RIGID);
}

// Rotating only about one axis leaves the translation along it undetermined; pure translations
// leave the rotation so (and, for points, the target offset inseparable from the camera).
TEST(HandEye, RefusesMotionsThatDoNotDetermineTheCamera) {
  const Isometry3d x = true_base_from_camera();
  const Isometry3d y = true_gripper_from_target();
  std::vector<PoseSample> one_axis;
  std::vector<PointSample> translations;
  for (int i = 0; i < 10; ++i) {
    Isometry3d a = Isometry3d::Identity();
    a.linear() = AngleAxisd(0.2 * i, Vector3d::UnitZ()).toRotationMatrix();
    a.translation() = Vector3d(0.3, -0.3, 0.2);
    one_axis.push_back({a, x.inverse() * a * y});
    Isometry3d t = Isometry3d::Identity();
    t.translation() = Vector3d(0.2 + 0.03 * i, -0.3 + 0.02 * (i % 3), 0.1 + 0.01 * (i % 4));
    translations.push_back({t, x.inverse() * (t * y.translation())});
  }
  EXPECT_EQ(solve_hand_eye(std::span<const PoseSample>(one_axis)).error(),
            HandEyeError::DEGENERATE_MOTION);
  EXPECT_EQ(solve_hand_eye(std::span<const PointSample>(translations)).error(),
            HandEyeError::DEGENERATE_MOTION);
  std::vector<PoseSample> still(5, one_axis.front());
  EXPECT_EQ(solve_hand_eye(std::span<const PoseSample>(still)).error(),
            HandEyeError::DEGENERATE_MOTION);
}

TEST(HandEye, EveryErrorHasAMessage) {
  for (const auto e :
       {HandEyeError::TOO_FEW_SAMPLES, HandEyeError::TOO_MANY_SAMPLES, HandEyeError::NOT_FINITE,
        HandEyeError::NOT_RIGID, HandEyeError::DEGENERATE_MOTION}) {
    EXPECT_EQ(std::string(to_string(e)).rfind("hand-eye: ", 0), 0U);
  }
}

}  // namespace
}  // namespace orthoflow::manipulation
