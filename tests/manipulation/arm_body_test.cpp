// The arm's capsules (manipulation/arm_body.hpp) with kernels::capsule_mask, in the camera frame of
// the synthetic session's robot frames: in 20 random arm poses every point of the link model's
// surface is removed, and no point farther from the arm than its radius plus the margin is.
// (The arm rendered into simulated depth frames, and the filter in the graph, are still to come:
// docs/MANIPULATION.md section 4.)
#include "manipulation/arm_body.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "manipulation/robot_frames.hpp"

namespace orthoflow::manipulation {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

struct Segment {
  Vector3d a, b;
  double radius;  // the physical model's, without the margin
};

// The skeleton in the base frame, from the chain's frames (what the link model is defined on).
std::vector<Segment> skeleton(const drivers::jaco::JointAngles& q, const ArmBodyModel& m) {
  const auto& g = drivers::jaco::jaco2_geometry();
  const auto frames = drivers::jaco::forward_kinematics_frames(q, g);
  std::vector<Segment> s;
  for (std::size_t k = 0; k < 6; ++k) {
    const Vector3d start = frames[k].translation();
    const Vector3d knee = start + g.rows[k].d_m * frames[k].linear().col(2);
    s.push_back({start, knee, m.link_radius_m[k]});
    s.push_back({knee, frames[k + 1].translation(), m.link_radius_m[k]});
  }
  const Vector3d axis = frames[6].linear().col(2);
  s.push_back({frames[6].translation() - m.hand_back_m * axis,
               frames[6].translation() + m.hand_front_m * axis, m.hand_radius_m});
  return s;
}

double distance_to(const Segment& s, const Vector3d& p) {
  const Vector3d d = s.b - s.a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - s.a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (p - s.a - t * d).norm();
}

TEST(ArmBody, TheArmsPointsAreRemovedAndNothingBeyondTheMargin) {
  const auto frames = load_robot_frames(ORTHOFLOW_SOURCE_DIR "/config/robot_frames_synthetic.yaml");
  ASSERT_TRUE(frames.has_value()) << frames.error();
  const Isometry3d& base_from_camera = frames.value().base_from_camera;
  const Isometry3d camera_from_base = base_from_camera.inverse();
  const ArmBodyModel model;
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> jog(-60.0, 60.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::size_t arm_points = 0, far_points = 0, near_points = 0;
  for (int pose = 0; pose < 20; ++pose) {
    drivers::jaco::JointAngles q = drivers::jaco::HOME_JOINTS;
    for (double& a : q) a += jog(rng);
    q[1] = std::clamp(q[1], 50.0, 310.0);
    q[2] = std::clamp(q[2], 22.0, 338.0);
    std::array<kernels::Capsule, ARM_BODY_CAPSULES> caps{};
    const std::size_t count =
        arm_body_capsules(q, base_from_camera, model, drivers::jaco::jaco2_geometry(), caps);
    EXPECT_EQ(count, 7U)
        << "JACO2: base column, upper arm, elbow offset, forearm, two wrist links, hand";
    const std::vector<Segment> body = skeleton(q, model);
    // Points on the physical surface (radius, no margin), and points around the arm.
    std::vector<float> x, y, z;
    std::vector<int> kind;  // 0: on the arm's surface, 1: beyond radius + margin, 2: in between
    for (const Segment& s : body) {
      if ((s.b - s.a).norm() == 0.0 && &s != &body.back()) continue;
      for (int i = 0; i < 200; ++i) {
        Vector3d dir(normal(rng), normal(rng), normal(rng));
        const Vector3d along = s.a + unit(rng) * (s.b - s.a);
        const Vector3d d = s.b - s.a;
        if (d.norm() > 0)
          dir -= dir.dot(d.normalized()) * d.normalized();  // perpendicular: on the side
        const Vector3d p = along + s.radius * dir.normalized();
        const Vector3d c = camera_from_base * p;
        x.push_back(float(c.x())), y.push_back(float(c.y())), z.push_back(float(c.z()));
        kind.push_back(0);
      }
    }
    for (int i = 0; i < 20000; ++i) {
      const Vector3d p(-0.9 + 1.8 * unit(rng), -0.9 + 1.8 * unit(rng), -0.1 + 1.2 * unit(rng));
      double nearest = 1e9;
      double margin_edge = 1e9;
      for (const Segment& s : body) {
        nearest = std::min(nearest, distance_to(s, p) - s.radius);
        margin_edge = std::min(margin_edge, distance_to(s, p) - s.radius - model.margin_m);
      }
      if (nearest <= 0.0) continue;  // inside the arm itself
      const Vector3d c = camera_from_base * p;
      x.push_back(float(c.x())), y.push_back(float(c.y())), z.push_back(float(c.z()));
      kind.push_back(margin_edge > 1e-4 ? 1 : (margin_edge < -1e-4 ? 2 : 3));
    }
    std::vector<std::uint8_t> mask(x.size());
    kernels::capsule_mask(kernels::PointsView{x, y, z}, std::span(caps).first(count), mask);
    for (std::size_t i = 0; i < mask.size(); ++i) {
      if (kind[i] == 0) {
        ++arm_points;
        EXPECT_EQ(mask[i], 0) << "pose " << pose << ": an arm point is left";
      } else if (kind[i] == 1) {
        ++far_points;
        EXPECT_EQ(mask[i], 1) << "pose " << pose << ": a point beyond radius + margin is lost";
      } else if (kind[i] == 2) {
        ++near_points;
        EXPECT_EQ(mask[i], 0) << "pose " << pose << ": a point within the margin is kept";
      }
    }
  }
  EXPECT_GT(arm_points, 20000U);
  EXPECT_GT(far_points, 300000U);
  EXPECT_GT(near_points, 1000U);
}

TEST(ArmBody, TheMarginAndTheHandAreHonoured) {
  ArmBodyModel model;
  model.margin_m = 0.0;
  std::array<kernels::Capsule, ARM_BODY_CAPSULES> caps{};
  const drivers::jaco::JointAngles home = drivers::jaco::HOME_JOINTS;
  const std::size_t n =
      arm_body_capsules(home, Isometry3d::Identity(), model, drivers::jaco::jaco2_geometry(), caps);
  ASSERT_EQ(n, 7U);
  EXPECT_FLOAT_EQ(caps[0].radius, 0.055F);
  const Isometry3d tool = drivers::jaco::forward_kinematics(home);
  const Vector3d tip = tool.translation() + 0.04 * tool.linear().col(2);
  EXPECT_NEAR(caps[n - 1].b[0], tip.x(), 1e-6);
  EXPECT_NEAR(caps[n - 1].b[2], tip.z(), 1e-6);
  model.margin_m = 0.03;
  (void)arm_body_capsules(home, Isometry3d::Identity(), model, drivers::jaco::jaco2_geometry(),
                          caps);
  EXPECT_FLOAT_EQ(caps[0].radius, 0.085F);
  EXPECT_FLOAT_EQ(caps[n - 1].radius, 0.09F);
}

TEST(ArmBody, AHeldObjectIsOneMoreCapsuleBelowTheHand) {
  const drivers::jaco::JointAngles home = drivers::jaco::HOME_JOINTS;
  const Isometry3d tool = drivers::jaco::forward_kinematics(home);
  ArmBodyModel model;
  std::array<kernels::Capsule, ARM_BODY_CAPSULES> caps{};
  const std::size_t bare =
      arm_body_capsules(home, Isometry3d::Identity(), model, drivers::jaco::jaco2_geometry(), caps);
  // A 0.08 x 0.06 x 0.20 box centred 5 cm below the tool point, upright.
  const HeldObject held = held_object(tool.translation(), tool.translation() - Vector3d(0, 0, 0.05),
                                      Vector3d(0.08, 0.06, 0.20), Vector3d::UnitZ());
  EXPECT_NEAR(held.radius_m, 0.05, 1e-12);
  EXPECT_TRUE(held.a.isApprox(Vector3d(0, 0, -0.15)));
  EXPECT_TRUE(held.b.isApprox(Vector3d(0, 0, 0.05)));
  const std::size_t with = arm_body_capsules(home, Isometry3d::Identity(), model,
                                             drivers::jaco::jaco2_geometry(), caps, held);
  ASSERT_EQ(with, bare + 1);
  const kernels::Capsule& c = caps[bare];
  EXPECT_NEAR(c.a[2], tool.translation().z() - 0.15, 1e-6);
  EXPECT_NEAR(c.b[2], tool.translation().z() + 0.05, 1e-6);
  EXPECT_NEAR(c.radius, 0.05 + model.margin_m, 1e-6);
}

TEST(ArmBody, AnArmBetweenTheCameraAndAnObjectOccludesIt) {
  const Vector3d eye = Vector3d::Zero();
  const Vector3d mug(0.0, 0.0, 1.2);  // 1.2 m in front of the camera
  // A forearm crossing the line of sight 40 cm in front of the camera.
  const std::array<kernels::Capsule, 1> across{{{{-0.2F, 0.0F, 0.4F}, {0.2F, 0.0F, 0.4F}, 0.05F}}};
  EXPECT_TRUE(occludes(across, eye, mug, 0.04));
  // The same forearm 15 cm to the side: clear of the line plus both radii (9 cm).
  const std::array<kernels::Capsule, 1> aside{{{{-0.2F, 0.15F, 0.4F}, {0.2F, 0.15F, 0.4F}, 0.05F}}};
  EXPECT_FALSE(occludes(aside, eye, mug, 0.04));
  // 8 cm to the side: within 5 + 4 cm of the line, it cuts the object's edge.
  const std::array<kernels::Capsule, 1> edge{{{{-0.2F, 0.08F, 0.4F}, {0.2F, 0.08F, 0.4F}, 0.05F}}};
  EXPECT_TRUE(occludes(edge, eye, mug, 0.04));
  // Behind the object (farther from the camera): no occlusion.
  const std::array<kernels::Capsule, 1> behind{{{{-0.2F, 0.0F, 1.4F}, {0.2F, 0.0F, 1.4F}, 0.05F}}};
  EXPECT_FALSE(occludes(behind, eye, mug, 0.04));
  EXPECT_FALSE(occludes({}, eye, mug, 0.04)) << "no arm";
  // A point-like capsule (both ends equal) on the line.
  const std::array<kernels::Capsule, 1> ball{{{{0.0F, 0.0F, 0.7F}, {0.0F, 0.0F, 0.7F}, 0.01F}}};
  EXPECT_TRUE(occludes(ball, eye, mug, 0.0));
}

}  // namespace
}  // namespace orthoflow::manipulation
