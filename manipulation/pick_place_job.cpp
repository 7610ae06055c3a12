#include "manipulation/pick_place_job.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace orthoflow::manipulation {

double finger_for_opening(double opening_m, const JobOptions& options) noexcept {
  const double max_open = options.grasp.hand.max_opening_m;
  const double share = std::clamp(opening_m / max_open, 0.0, 1.0);
  return (1.0 - share) * options.finger_closed;
}

std::size_t cover_box(const ObjectBox& box, std::span<Obstacle> out) noexcept {
  const Eigen::Vector3d e = box.extents.cwiseMax(0.0);
  const double cell = std::max(0.03, e.maxCoeff() / 4.0);
  Eigen::Array3i n;
  Eigen::Vector3d size;
  for (int k = 0; k < 3; ++k) {
    n[k] = static_cast<int>(std::clamp(std::ceil(e[k] / cell), 1.0, 4.0));
    size[k] = e[k] / n[k];
  }
  const double radius = 0.5 * size.norm();
  std::size_t count = 0;
  for (int i = 0; i < n[0]; ++i) {
    for (int j = 0; j < n[1]; ++j) {
      for (int k = 0; k < n[2] && count < out.size(); ++k) {
        const Eigen::Vector3d local =
            (Eigen::Array3d(i, j, k) + 0.5).matrix().cwiseProduct(size) - 0.5 * e;
        out[count++] = {box.base_from_object * local, radius};
      }
    }
  }
  return count;
}

double opening_for_finger(double finger, const JobOptions& options) noexcept {
  const double share = std::clamp(finger / options.finger_closed, 0.0, 1.0);
  return (1.0 - share) * options.grasp.hand.max_opening_m;
}

Result<PickPlaceJob, std::string> make_pick_place_job(std::uint32_t track_id,
                                                      const Eigen::Vector3d& target_centre,
                                                      const Grasp& grasp,
                                                      const Eigen::Vector3d& place_centre,
                                                      const JobOptions& options) noexcept {
  if (!target_centre.allFinite() || !place_centre.allFinite() ||
      !grasp.grasp.matrix().allFinite() || !std::isfinite(options.lift_m))
    return err(std::string("a job needs finite centres, grasp and lift"));
  const drivers::jaco::ArmGeometry& geometry =
      options.grasp.geometry != nullptr ? *options.grasp.geometry : drivers::jaco::jaco2_geometry();
  const SupportPlane& table = options.grasp.table;
  const Eigen::Vector3d up = table.normal.normalized();
  PickPlaceJob job;
  job.track_id = track_id;
  job.target_centre = target_centre;
  job.up = up;
  job.initial = options.initial;
  job.pre_grasp = grasp.pre_grasp_joints;
  job.grasp = grasp.grasp_joints;
  job.lift_m = options.lift_m;
  job.open_fingers = finger_for_opening(grasp.opening_m, options);
  job.close_fingers = finger_for_opening(options.close_to_m, options);
  job.touch_fingers = finger_for_opening(grasp.opening_m - options.touch_travel_m, options);
  // The place keeps the object's height above the table: the same offset from the grasp centre.
  Eigen::Vector3d shift = place_centre - target_centre;
  shift -= shift.dot(up) * up;  // along the table only
  const Eigen::Isometry3d lift = carry_pose(grasp, table, options.lift_m);
  Eigen::Isometry3d carry = lift;
  carry.translation() += shift;
  Eigen::Isometry3d place = grasp.grasp;
  place.translation() += shift;
  Eigen::Isometry3d retreat = place;
  retreat.translation() -= options.grasp.pre_grasp_distance_m * grasp.approach.normalized();
  const struct {
    const char* name;
    const Eigen::Isometry3d* pose;
    drivers::jaco::JointAngles* out;
  } steps[] = {{"lift", &lift, &job.lift},
               {"carry", &carry, &job.carry},
               {"place", &place, &job.place},
               {"retreat", &retreat, &job.retreat}};
  drivers::jaco::JointAngles seed = grasp.grasp_joints;
  for (const auto& s : steps) {
    auto q = drivers::jaco::inverse_kinematics(*s.pose, seed, options.grasp.limits,
                                               options.grasp.tolerance, geometry);
    if (!q && s.out == &job.retreat) {
      // Back along the approach is out of reach: the open hand rises off the object instead (its
      // fingers are open wider than the object).
      Eigen::Isometry3d up_and_away = place;
      up_and_away.translation() += options.grasp.pre_grasp_distance_m * up;
      q = drivers::jaco::inverse_kinematics(up_and_away, seed, options.grasp.limits,
                                            options.grasp.tolerance, geometry);
    }
    if (!q) return err(std::string(s.name) + ": " + drivers::jaco::to_string(q.error()));
    *s.out = *q;
    seed = *q;
  }
  return job;
}

Result<void, std::string> add_way_in_from_above(PickPlaceJob& job, const Grasp& grasp,
                                                double height_m,
                                                const JobOptions& options) noexcept {
  if (!std::isfinite(height_m) || height_m <= 0.0)
    return err(std::string("a way in from above needs a positive height"));
  const drivers::jaco::ArmGeometry& geometry =
      options.grasp.geometry != nullptr ? *options.grasp.geometry : drivers::jaco::jaco2_geometry();
  Eigen::Isometry3d above = grasp.pre_grasp;
  above.translation() += height_m * options.grasp.table.normal.normalized();
  auto q = drivers::jaco::inverse_kinematics(above, job.pre_grasp, options.grasp.limits,
                                             options.grasp.tolerance, geometry);
  if (!q) return err(std::string("above the pre-grasp: ") + drivers::jaco::to_string(q.error()));
  job.via_above = true;
  job.above_pre_grasp = *q;
  return {};
}

Result<void, std::string> add_rise_first(PickPlaceJob& job, const drivers::jaco::JointAngles& now,
                                         double height_m, const JobOptions& options) noexcept {
  if (!std::isfinite(height_m) || height_m <= 0.0)
    return err(std::string("a rise needs a positive height"));
  const drivers::jaco::ArmGeometry& geometry =
      options.grasp.geometry != nullptr ? *options.grasp.geometry : drivers::jaco::jaco2_geometry();
  Eigen::Isometry3d risen = drivers::jaco::forward_kinematics(now, geometry);
  risen.translation() += height_m * options.grasp.table.normal.normalized();
  auto q = drivers::jaco::inverse_kinematics(risen, now, options.grasp.limits,
                                             options.grasp.tolerance, geometry);
  if (!q) return err(std::string("the rise: ") + drivers::jaco::to_string(q.error()));
  job.rise_first = true;
  job.risen = *q;
  return {};
}

Result<void, std::string> add_way_round(PickPlaceJob& job, const Grasp& grasp, double side_m,
                                        const JobOptions& options) noexcept {
  if (!std::isfinite(side_m) || side_m == 0.0)
    return err(std::string("a way round needs a finite, non-zero side"));
  const drivers::jaco::ArmGeometry& geometry =
      options.grasp.geometry != nullptr ? *options.grasp.geometry : drivers::jaco::jaco2_geometry();
  const Eigen::Vector3d up = options.grasp.table.normal.normalized();
  const Eigen::Vector3d from = drivers::jaco::forward_kinematics(job.lift, geometry).translation();
  const Eigen::Vector3d to = drivers::jaco::forward_kinematics(job.carry, geometry).translation();
  Eigen::Vector3d along = to - from;
  along -= along.dot(up) * up;
  if (along.norm() < 0.02) return err(std::string("the carry is too short to go round"));
  Eigen::Isometry3d aside = carry_pose(grasp, options.grasp.table, job.lift_m);
  aside.translation() = 0.5 * (from + to) + side_m * up.cross(along.normalized());
  auto q = drivers::jaco::inverse_kinematics(aside, job.lift, options.grasp.limits,
                                             options.grasp.tolerance, geometry);
  if (!q) return err(std::string("beside the carry: ") + drivers::jaco::to_string(q.error()));
  job.via_aside = true;
  job.aside = *q;
  return {};
}

Result<void, std::string> check_job_paths(const PickPlaceJob& job,
                                          const drivers::jaco::JointAngles& now,
                                          std::span<const Obstacle> others, double clearance_m,
                                          const drivers::jaco::SafetyLimits& limits) {
  const struct {
    const char* name;
    const drivers::jaco::JointAngles* from;
    const drivers::jaco::JointAngles* to;
    bool straight;
  } moves[] = {{"rise", &now, &job.risen, true},
               {"initial", job.rise_first ? &job.risen : &now, &job.initial, false},
               {job.via_above ? "above the pre_grasp" : "pre_grasp", &job.initial,
                job.via_above ? &job.above_pre_grasp : &job.pre_grasp, false},
               {"down to the pre_grasp", &job.above_pre_grasp, &job.pre_grasp, true},
               {"approach", &job.pre_grasp, &job.grasp, true},
               {"lift", &job.grasp, &job.lift, true},
               {"carry", &job.lift, job.via_aside ? &job.aside : &job.carry, false},
               {"carry on from beside", &job.aside, &job.carry, false},
               {"place", &job.carry, &job.place, true},
               {"retreat", &job.place, &job.retreat, true}};
  for (const auto& m : moves) {
    if ((m.from == &job.above_pre_grasp && !job.via_above) ||
        (m.to == &job.risen && !job.rise_first) || (m.from == &job.aside && !job.via_aside))
      continue;
    if (auto safe = drivers::jaco::check_joint_move(limits, *m.from, *m.to); !safe)
      return err(std::string(m.name) + ": " + drivers::jaco::describe(safe.error()));
    if (joint_path_blocked(*m.from, *m.to, others, clearance_m))
      return err(std::string(m.name) + ": passes another object");
    if (const double swing = joint_path_deviation(*m.from, *m.to);
        m.straight && swing > MAX_SWING_M) {
      char text[96];
      std::snprintf(text, sizeof text, ": the hand would swing %.2f m off its straight line",
                    swing);
      return err(std::string(m.name) + text);
    }
  }
  return {};
}

}  // namespace orthoflow::manipulation
