#include "manipulation/grasp_planner.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "manipulation/rigid.hpp"

namespace orthoflow::manipulation {
namespace {

using drivers::jaco::JointAngles;
using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double RIGID_TOLERANCE = 1e-4;  // the payload carries floats

double joint_distance(const JointAngles& a, const JointAngles& b) noexcept {
  double sum = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) { sum += (a[k] - b[k]) * (a[k] - b[k]); }
  return std::sqrt(sum);
}

// The box's extent along a unit direction: the sum of its edges' projections.
double extent_along(const ObjectBox& box, const Vector3d& direction) noexcept {
  const Matrix3d r = box.base_from_object.linear();
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) { sum += std::abs(direction.dot(r.col(k))) * box.extents[k]; }
  return sum;
}

Isometry3d hand_pose(const Vector3d& centre, const Vector3d& approach, const Vector3d& closing,
                     double tcp_offset_m) noexcept {
  Isometry3d pose = Isometry3d::Identity();
  pose.linear().col(0) = closing.cross(approach);
  pose.linear().col(1) = closing;
  pose.linear().col(2) = approach;
  pose.translation() = centre - tcp_offset_m * approach;
  return pose;
}

// A candidate before the IK: kind, approach and closing directions, the grasp centre.
struct Candidate {
  GraspKind kind;
  Vector3d approach;
  Vector3d closing;
  Vector3d centre;
  double width;
  /// The box's larger horizontal extent: a partial view shows an object's width across the view
  /// but half its depth, so the hand opens to this, not to the width (issue 51: the fingers met a
  /// bottle's far side on the way in).
  double span;
};

struct Planner {
  const ObjectBox& box;
  const GraspOptions& options;
  const drivers::jaco::ArmGeometry& geometry;
  GraspPlan& plan;

  void reject(const Candidate& c, GraspRejection reason) const noexcept {
    plan.rejected[plan.rejected_count++] = {c.kind, c.approach, c.width, reason};
  }

  // Both rolls of the hand about its approach (the closing axis either way); the one with the
  // least joint travel wins.
  void solve(const Candidate& c) const noexcept {
    const HandModel& hand = options.hand;
    if (c.width < hand.min_width_m) {
      reject(c, GraspRejection::TOO_THIN);
      return;
    }
    if (c.width > hand.max_opening_m - hand.min_clearance_m) {
      reject(c, GraspRejection::TOO_WIDE);
      return;
    }
    bool pre_reached = false;
    std::optional<Grasp> best;
    for (const double sign : {1.0, -1.0}) {
      const Vector3d closing = sign * c.closing;
      const Isometry3d grasp = hand_pose(c.centre, c.approach, closing, hand.tcp_offset_m);
      const Isometry3d pre = hand_pose(c.centre - options.pre_grasp_distance_m * c.approach,
                                       c.approach, closing, hand.tcp_offset_m);
      const auto pre_joints = drivers::jaco::inverse_kinematics(pre, options.seed, options.limits,
                                                                options.tolerance, geometry);
      if (!pre_joints.has_value()) { continue; }
      pre_reached = true;
      const auto grasp_joints = drivers::jaco::inverse_kinematics(
          grasp, pre_joints.value(), options.limits, options.tolerance, geometry);
      if (!grasp_joints.has_value()) { continue; }
      Grasp g;
      g.kind = c.kind;
      g.pre_grasp = pre;
      g.grasp = grasp;
      g.approach = c.approach;
      g.width_m = c.width;
      g.opening_m = std::min(std::max(c.width, c.span) + hand.clearance_m, hand.max_opening_m);
      g.pre_grasp_joints = pre_joints.value();
      g.grasp_joints = grasp_joints.value();
      g.joint_travel_deg = joint_distance(options.seed, g.pre_grasp_joints) +
                           joint_distance(g.pre_grasp_joints, g.grasp_joints);
      if (!best || g.joint_travel_deg < best->joint_travel_deg) { best = g; }
    }
    if (!best) {
      reject(c, pre_reached ? GraspRejection::UNREACHABLE_GRASP
                            : GraspRejection::UNREACHABLE_PRE_GRASP);
      return;
    }
    plan.feasible[plan.feasible_count++] = *best;
  }
};

bool options_finite(const GraspOptions& o) noexcept {
  return o.table.normal.allFinite() && std::isfinite(o.table.offset) &&
         o.table.normal.norm() > 1e-9 &&
         std::all_of(o.seed.begin(), o.seed.end(), [](double q) { return std::isfinite(q); });
}

}  // namespace

const char* to_string(GraspKind kind) noexcept { return kind == GraspKind::TOP ? "top" : "side"; }

const char* to_string(GraspRejection reason) noexcept {
  switch (reason) {
    case GraspRejection::TOO_WIDE:
      return "too wide for the hand";
    case GraspRejection::TOO_THIN:
      return "too thin to grasp";
    case GraspRejection::HITS_TABLE:
      return "the fingers would reach the table before covering the object";
    case GraspRejection::UNREACHABLE_PRE_GRASP:
      return "pre-grasp outside the reachable workspace (no IK solution within the joint limits)";
    case GraspRejection::UNREACHABLE_GRASP:
      return "grasp pose outside the reachable workspace (no IK solution within the joint limits)";
  }
  return "unknown";
}

const char* to_string(ObjectRejection reason) noexcept {
  switch (reason) {
    case ObjectRejection::NOT_FINITE:
      return "the object's box, the table or the seed holds NaN or infinity, or the table's normal "
             "is zero";
    case ObjectRejection::NOT_RIGID:
      return "the object's frame is not a rotation";
    case ObjectRejection::BAD_EXTENTS:
      return "the object's box has a negative or all-zero size";
    case ObjectRejection::INSIDE_TABLE:
      return "the object's box reaches into the table";
    case ObjectRejection::OUT_OF_REACH:
      return "the object is farther from the shoulder than the arm reaches";
  }
  return "unknown";
}

ObjectBox object_box_in_base(const Eigen::Isometry3d& base_from_camera,
                             const std::array<float, 16>& object_from_camera_row_major,
                             const std::array<float, 3>& extents) noexcept {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      m(r, c) = object_from_camera_row_major[static_cast<std::size_t>(4 * r + c)];
    }
  }
  Isometry3d object_from_camera = Isometry3d::Identity();
  object_from_camera.linear() = m.topLeftCorner<3, 3>();
  object_from_camera.translation() = m.topRightCorner<3, 1>();
  ObjectBox box;
  box.base_from_object = base_from_camera * object_from_camera.inverse(Eigen::Isometry);
  // A frame built from eigenvectors with independent sign choices may be a reflection; the box is
  // symmetric, so flipping one axis describes the same box with a proper rotation.
  if (box.base_from_object.linear().determinant() < 0.0) {
    box.base_from_object.linear().col(2) *= -1.0;
  }
  box.extents = Vector3d(extents[0], extents[1], extents[2]);
  return box;
}

ObjectBox upright_box(const ObjectBox& box, const SupportPlane& table) noexcept {
  const Vector3d up = table.normal.normalized();
  const Eigen::Matrix3d r = box.base_from_object.linear();
  int vertical = 0;  // the box axis nearest the table's normal: the object's height
  for (int k = 1; k < 3; ++k) {
    if (std::fabs(r.col(k).dot(up)) > std::fabs(r.col(vertical).dot(up))) vertical = k;
  }
  const int a = (vertical + 1) % 3, b = (vertical + 2) % 3;
  Vector3d x = r.col(a) - r.col(a).dot(up) * up;
  x = x.norm() > 1e-9 ? x.normalized() : up.unitOrthogonal();
  ObjectBox out;
  out.base_from_object.linear().col(0) = x;
  out.base_from_object.linear().col(1) = up.cross(x);
  out.base_from_object.linear().col(2) = up;
  out.extents = Vector3d(box.extents[a], box.extents[b], box.extents[vertical]);
  // The same centre, raised if the box's bottom would be below the table (it stands on it).
  Vector3d centre = box.base_from_object.translation();
  const double bottom = table.height_of(centre) - 0.5 * out.extents.z();
  if (bottom < 0.0) centre -= bottom * up;
  out.base_from_object.translation() = centre;
  return out;
}

Result<GraspPlan, ObjectRejection> plan_grasp(const ObjectBox& box,
                                              const GraspOptions& options) noexcept {
  if (!box.base_from_object.matrix().allFinite() || !box.extents.allFinite() ||
      !options_finite(options)) {
    return err(ObjectRejection::NOT_FINITE);
  }
  if (!is_rigid(box.base_from_object, RIGID_TOLERANCE)) { return err(ObjectRejection::NOT_RIGID); }
  const Matrix3d r = box.base_from_object.linear();
  if ((box.extents.array() < 0.0).any() || box.extents.maxCoeff() <= 0.0) {
    return err(ObjectRejection::BAD_EXTENTS);
  }
  const drivers::jaco::ArmGeometry& geometry =
      options.geometry != nullptr ? *options.geometry : drivers::jaco::jaco2_geometry();
  const double normal_norm = options.table.normal.norm();
  const Vector3d up = options.table.normal / normal_norm;
  const SupportPlane table{up, options.table.offset / normal_norm};
  const Vector3d centre = box.base_from_object.translation();
  const double height = extent_along(box, up);
  const double centre_height = table.height_of(centre);
  const double top = centre_height + 0.5 * height;
  if (centre_height - 0.5 * height < -options.max_penetration_m) {
    return err(ObjectRejection::INSIDE_TABLE);
  }
  const Vector3d shoulder(0.0, 0.0, std::abs(geometry.rows[0].d_m));
  if ((centre - shoulder).norm() > options.reach_m) { return err(ObjectRejection::OUT_OF_REACH); }

  // The horizontal principal directions: the most horizontal object axis, projected onto the table,
  // and its perpendicular in the table.
  Vector3d d1 = Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const Vector3d h = r.col(k) - r.col(k).dot(up) * up;
    if (h.norm() > d1.norm()) { d1 = h; }
  }
  d1.normalize();
  const Vector3d d2 = up.cross(d1);
  const double w1 = extent_along(box, d1);
  const double w2 = extent_along(box, d2);

  GraspPlan plan;
  plan.preferred = height > std::min(w1, w2) ? GraspKind::SIDE : GraspKind::TOP;
  const Planner planner{box, options, geometry, plan};
  const HandModel& hand = options.hand;
  // The grasp centre's height over the table: the fingertips above the table, the pads at least
  // min_grip_depth below the box top.
  const double lowest = hand.fingertip_extent_m + hand.table_clearance_m;
  const auto place = [&](const Candidate& base_candidate, double wanted_height) {
    Candidate c = base_candidate;
    const double h = std::max(wanted_height, lowest);
    c.centre = centre + (h - centre_height) * up;
    if (top - h < hand.min_grip_depth_m) {
      planner.reject(c, GraspRejection::HITS_TABLE);
      return;
    }
    planner.solve(c);
  };

  // Top grasps: straight down, the fingers wrapping the top finger_reach of the box.
  for (const Vector3d& closing : {d1, d2}) {
    const Candidate c{GraspKind::TOP,  -up, closing, centre, extent_along(box, closing),
                      std::max(w1, w2)};
    place(c, std::max(centre_height, top - hand.finger_reach_m));
  }
  // Side grasps: horizontally along a principal direction, from the arm's side of the object.
  Vector3d radial = centre - centre.dot(up) * up;
  const bool has_radial = radial.norm() > 1e-6;
  radial = has_radial ? radial.normalized() : Vector3d::Zero();
  for (const Vector3d& approach : {d1, Vector3d(-d1), d2, Vector3d(-d2)}) {
    if (has_radial && approach.dot(radial) < -1e-9) { continue; }
    const Vector3d closing = up.cross(approach);
    const Candidate c{GraspKind::SIDE, approach, closing, centre, extent_along(box, closing),
                      std::max(w1, w2)};
    place(c, centre_height);
  }

  std::stable_sort(plan.feasible.begin(),
                   plan.feasible.begin() + static_cast<std::ptrdiff_t>(plan.feasible_count),
                   [&](const Grasp& a, const Grasp& b) {
                     const bool a_pref = a.kind == plan.preferred;
                     const bool b_pref = b.kind == plan.preferred;
                     if (a_pref != b_pref) { return a_pref; }
                     return a.joint_travel_deg < b.joint_travel_deg;
                   });
  return plan;
}

Eigen::Isometry3d carry_pose(const Grasp& grasp, const SupportPlane& table,
                             double lift_m) noexcept {
  Isometry3d pose = grasp.grasp;
  pose.translation() += lift_m * table.normal.normalized();
  return pose;
}

}  // namespace orthoflow::manipulation
