#pragma once
/// @file
/// @brief Grasp planning from an object's box (thesis chapter 2, "Coupling Object Perception with
/// Manipulation"; issue 21, item 2): a top or side grasp aligned with the object's principal axes,
/// a pre-grasp d = 0.15 m above or behind the box centre, the finger opening from the box's width
/// across the fingers, reachability by the JACO's inverse kinematics. Every candidate that is not
/// feasible is kept with the reason.
///
/// Frames (all in the arm's base frame, metres): the hand pose is the pose the arm's Cartesian
/// command names (drivers/jaco/jaco_kinematics.hpp: the DH end-effector frame), taken as the grasp
/// centre between the finger pads (HandModel::tcp_offset_m moves it along the approach). Its z
/// axis is the approach direction; its y axis is the direction the fingers close along; x = y * z.
/// The box is centred at its frame's origin (for a GOOD frame: the object's centroid), with full
/// edge lengths along the frame's axes.
///
/// Carrying keeps the grasped object parallel to the table: a top grasp approaches along -up and
/// a side grasp approaches and closes horizontally, so the execution manager lifts, carries and
/// places with the grasp's orientation unchanged (carry_pose) and the object's up stays up.
///
/// Pure functions, no state; no allocation (fixed arrays); deterministic.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"

namespace orthoflow::manipulation {

/// @brief The JACO's three-finger hand as the planner sees it. The defaults are conservative
/// planning values, not vendor figures: measure the hand in use and set them.
struct HandModel {
  double max_opening_m = 0.14;        ///< widest finger opening at the pads
  double min_width_m = 0.01;          ///< a thinner object is not grasped reliably
  double clearance_m = 0.02;          ///< the opening exceeds the width by this much when it can
  double min_clearance_m = 0.005;     ///< the least margin an opening may keep (else TOO_WIDE)
  double finger_reach_m = 0.05;       ///< how far along the approach the fingers wrap an object
  double fingertip_extent_m = 0.015;  ///< how far the fingertips reach past the grasp centre
  double table_clearance_m = 0.005;   ///< fingertips stay this far above the table
  double min_grip_depth_m = 0.015;    ///< the fingers must cover at least this much of the box
  double tcp_offset_m = 0.0;  ///< grasp centre minus the tool frame's origin, along the approach
};

/// @brief The support plane in the base frame: normal . p + offset = 0, normal pointing up (away
/// from the table). The default: the arm stands on the table (JACO.md 8: base origin at the
/// bottom face, +z up).
struct SupportPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  [[nodiscard]] double height_of(const Eigen::Vector3d& p) const noexcept {
    return normal.dot(p) + offset;
  }
};

/// @brief An object's oriented box in the base frame.
struct ObjectBox {
  Eigen::Isometry3d base_from_object = Eigen::Isometry3d::Identity();
  Eigen::Vector3d extents = Eigen::Vector3d::Zero();  ///< full edge lengths along the object axes
};
/// @brief The box of a GOOD frame (world -> object, row-major, as kernels::GoodResult::frame and
/// engine::ObjectEntry::frame carry it) and its edge lengths, seen by a camera at
/// @p base_from_camera. @pre none (non-finite input gives a non-finite box, which plan_grasp
/// refuses).
[[nodiscard]] ObjectBox object_box_in_base(
    const Eigen::Isometry3d& base_from_camera,
    const std::array<float, 16>& object_from_camera_row_major,
    const std::array<float, 3>& extents) noexcept;

/// @brief The upright box of an object standing on @p table: the box axis nearest the table's
/// normal becomes the height (z along the normal), the next axis projected onto the table becomes
/// x; the extents keep their lengths (a GOOD box is tight along its own axes, a box around a
/// tilted box is not), and a box whose bottom would be below the table is raised onto it. A GOOD
/// frame of a partial view is often tilted; the planner and the orientation constraint want the
/// object upright. @pre finite input.
[[nodiscard]] ObjectBox upright_box(const ObjectBox& box, const SupportPlane& table) noexcept;

enum class GraspKind : std::uint8_t { TOP, SIDE };
[[nodiscard]] const char* to_string(GraspKind kind) noexcept;

/// @brief A feasible grasp: poses, opening, and the joint solutions the IK found for them.
struct Grasp {
  GraspKind kind = GraspKind::TOP;
  Eigen::Isometry3d pre_grasp = Eigen::Isometry3d::Identity();  ///< hand pose, base frame
  Eigen::Isometry3d grasp = Eigen::Isometry3d::Identity();      ///< hand pose, base frame
  Eigen::Vector3d approach = -Eigen::Vector3d::UnitZ();         ///< unit, base frame
  double width_m = 0.0;    ///< the box's extent across the fingers
  double opening_m = 0.0;  ///< finger opening to command before the approach
  drivers::jaco::JointAngles pre_grasp_joints{};
  drivers::jaco::JointAngles grasp_joints{};
  double joint_travel_deg = 0.0;  ///< seed to pre-grasp plus pre-grasp to grasp, joint space
};

/// @brief Why a candidate grasp is not feasible.
enum class GraspRejection : std::uint8_t {
  TOO_WIDE,               ///< the box is wider across the fingers than the hand opens
  TOO_THIN,               ///< narrower than HandModel::min_width_m
  HITS_TABLE,             ///< the fingertips would reach the table before covering the box
  UNREACHABLE_PRE_GRASP,  ///< no joint solution within the limits reaches the pre-grasp
  UNREACHABLE_GRASP,      ///< ... the grasp pose (from the pre-grasp's solution)
};
[[nodiscard]] const char* to_string(GraspRejection reason) noexcept;

/// @brief A candidate that is not feasible, and why.
struct RejectedGrasp {
  GraspKind kind = GraspKind::TOP;
  Eigen::Vector3d approach = Eigen::Vector3d::Zero();
  double width_m = 0.0;
  GraspRejection reason = GraspRejection::TOO_WIDE;
};

/// @brief Two top candidates (closing along either horizontal principal direction) and up to four
/// side ones (approaching along a horizontal principal direction away from the arm).
inline constexpr std::size_t MAX_GRASP_CANDIDATES = 6;

/// @brief Every candidate, feasible ones best first.
struct GraspPlan {
  std::array<Grasp, MAX_GRASP_CANDIDATES> feasible{};
  std::size_t feasible_count = 0;
  std::array<RejectedGrasp, MAX_GRASP_CANDIDATES> rejected{};
  std::size_t rejected_count = 0;
  GraspKind preferred = GraspKind::TOP;  ///< the kind the object's shape favours
  [[nodiscard]] const Grasp* best() const noexcept {
    return feasible_count > 0 ? &feasible[0] : nullptr;
  }
};

/// @brief Why an object gets no plan at all.
enum class ObjectRejection : std::uint8_t {
  NOT_FINITE,    ///< the box, table or seed holds NaN or infinity, or the normal is zero
  NOT_RIGID,     ///< the box's rotation is not a rotation
  BAD_EXTENTS,   ///< an edge length is negative, or every one is zero
  INSIDE_TABLE,  ///< the box reaches deeper into the table than max_penetration_m
  OUT_OF_REACH,  ///< the box centre is farther from the shoulder than the arm reaches
};
[[nodiscard]] const char* to_string(ObjectRejection reason) noexcept;

/// @brief Everything the planner needs besides the object.
struct GraspOptions {
  HandModel hand{};
  SupportPlane table{};
  double pre_grasp_distance_m = 0.15;  ///< thesis: d_pre-grasp = 0.15 m
  double max_penetration_m = 0.02;     ///< a box bottom this far below the table is refused
  double reach_m = 0.90;  ///< shoulder to tool at full stretch (JACO2: 0.41 + 0.21 + 0.28)
  drivers::jaco::JointAngles seed = drivers::jaco::HOME_JOINTS;  ///< the current joints
  const drivers::jaco::ArmGeometry* geometry = nullptr;          ///< null: the JACO2
  drivers::jaco::JointLimits limits = drivers::jaco::jaco_joint_limits();
  drivers::jaco::IkTolerance tolerance{};
};

/// @brief Plans the grasps of @p box. Feasible candidates come best first: the preferred kind
/// (side for a box taller than it is wide across its narrower horizontal direction, else top),
/// then the least joint travel. @pre options' lengths positive and finite.
[[nodiscard]] Result<GraspPlan, ObjectRejection> plan_grasp(const ObjectBox& box,
                                                            const GraspOptions& options) noexcept;

/// @brief @p grasp's hand pose moved by @p lift_m along the table's normal, orientation
/// unchanged: the lift and the carry of the orientation constraint. @pre finite values.
[[nodiscard]] Eigen::Isometry3d carry_pose(const Grasp& grasp, const SupportPlane& table,
                                           double lift_m) noexcept;

}  // namespace orthoflow::manipulation
