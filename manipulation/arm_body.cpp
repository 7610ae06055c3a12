#include "manipulation/arm_body.hpp"

#include "manipulation/segment_distance.hpp"

#include <cmath>

namespace orthoflow::manipulation {
namespace {

kernels::Capsule capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         double radius) noexcept {
  return {{static_cast<float>(a.x()), static_cast<float>(a.y()), static_cast<float>(a.z())},
          {static_cast<float>(b.x()), static_cast<float>(b.y()), static_cast<float>(b.z())},
          static_cast<float>(radius)};
}

}  // namespace

std::size_t arm_body_capsules(const drivers::jaco::JointAngles& joints,
                              const Eigen::Isometry3d& base_from_camera, const ArmBodyModel& model,
                              const drivers::jaco::ArmGeometry& geometry,
                              std::span<kernels::Capsule, ARM_BODY_CAPSULES> out,
                              const HeldObject& held) noexcept {
  const Eigen::Isometry3d camera_from_base = base_from_camera.inverse(Eigen::Isometry);
  const drivers::jaco::ChainFrames frames =
      drivers::jaco::forward_kinematics_frames(joints, geometry);
  std::size_t n = 0;
  for (std::size_t k = 0; k < 6; ++k) {
    const drivers::jaco::DhRow& row = geometry.rows[k];
    const double radius = model.link_radius_m[k] + model.margin_m;
    const Eigen::Vector3d start = frames[k].translation();
    const Eigen::Vector3d knee = start + row.d_m * frames[k].linear().col(2);
    const Eigen::Vector3d end = frames[k + 1].translation();
    if (std::abs(row.d_m) > 0.0) {
      out[n++] = capsule(camera_from_base * start, camera_from_base * knee, radius);
    }
    if (std::abs(row.a_m) > 0.0) {
      out[n++] = capsule(camera_from_base * knee, camera_from_base * end, radius);
    }
  }
  const Eigen::Isometry3d& tool = frames[6];
  const Eigen::Vector3d axis = tool.linear().col(2);
  out[n++] = capsule(camera_from_base * (tool.translation() - model.hand_back_m * axis),
                     camera_from_base * (tool.translation() + model.hand_front_m * axis),
                     model.hand_radius_m + model.margin_m);
  if (held.held()) {
    out[n++] =
        capsule(camera_from_base * (tool.translation() + held.a),
                camera_from_base * (tool.translation() + held.b), held.radius_m + model.margin_m);
  }
  return n;
}

bool occludes(std::span<const kernels::Capsule> capsules, const Eigen::Vector3d& eye,
              const Eigen::Vector3d& target, double target_radius_m) noexcept {
  for (const kernels::Capsule& c : capsules) {
    const Eigen::Vector3d a(c.a[0], c.a[1], c.a[2]);
    const Eigen::Vector3d b(c.b[0], c.b[1], c.b[2]);
    for (std::size_t s = 0; s <= SIGHT_SAMPLES; ++s) {
      const Eigen::Vector3d p =
          eye + (static_cast<double>(s) / static_cast<double>(SIGHT_SAMPLES)) * (target - eye);
      if (distance_to_segment(a, b, p) < c.radius + target_radius_m) return true;
    }
  }
  return false;
}

HeldObject held_object(const Eigen::Vector3d& tool, const Eigen::Vector3d& centre,
                       const Eigen::Vector3d& extents, const Eigen::Vector3d& up) noexcept {
  const Eigen::Vector3d u = up.normalized();
  HeldObject h;
  h.a = centre - 0.5 * extents.z() * u - tool;
  h.b = centre + 0.5 * extents.z() * u - tool;
  h.radius_m = 0.5 * extents.head<2>().norm();
  return h;
}

}  // namespace orthoflow::manipulation
