#pragma once
/// @file
/// @brief A pick-and-place job for the execution manager from a planned grasp: every pose of the
/// sequence solved in joint space before anything moves (thesis chapter 2): the lift straight up
/// from the grasp, the carry at that height to above the place, the place straight down, the
/// retreat back along the approach; the hand's orientation never changes from the grasp on (the
/// object stays upright). Finger commands from the opening and the width (a linear map of the
/// finger range onto the hand's opening, a planning approximation, not a vendor figure).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "drivers/jaco/jaco_safety.hpp"
#include "manipulation/execution_manager.hpp"
#include "manipulation/grasp_planner.hpp"

namespace orthoflow::manipulation {

/// @brief What a job needs besides the grasp.
struct JobOptions {
  GraspOptions grasp{};  ///< the planner's options: table, hand, limits, geometry
  drivers::jaco::JointAngles initial = drivers::jaco::HOME_JOINTS;
  double lift_m = 0.10;  ///< lift and carry height above the grasp
  /// The fingers' goal when closing, as an opening (m); 0: closed. The object between them stops
  /// them short of it (the driver sees the stall: fingers_blocked) at its width where the hand
  /// holds it, which the perceived box does not tell (a bottle's neck under a top grasp is
  /// narrower than its body); a hand that reaches this goal held nothing (issue 51).
  double close_to_m = 0.0;
  /// Fingers that stall before closing this far from the open hand were blocked where they
  /// started, not closed on the object (the hand opens 2 cm wider than the object when it can).
  double touch_travel_m = 0.01;
  double finger_closed = 6400.0;  ///< the model's finger value when closed (JACO2 ~6400)
};

/// @brief The job for @p grasp of the object @p track_id centred at @p target_centre, placed with
/// its centre at @p place_centre (base frame; the height comes from the table). @return the step
/// whose pose the arm does not reach ("carry: ..."), or a non-finite input.
[[nodiscard]] Result<PickPlaceJob, std::string> make_pick_place_job(
    std::uint32_t track_id, const Eigen::Vector3d& target_centre, const Grasp& grasp,
    const Eigen::Vector3d& place_centre, const JobOptions& options) noexcept;

/// @brief Gives @p job (made from @p grasp) a way in from above: its pre-grasp pose raised
/// @p height_m along the table's normal, which the manager reaches before the pre-grasp (the hand
/// then comes straight down to it), for when the direct way to the pre-grasp passes another
/// object. @return the IK error of the raised pose (the job is unchanged then).
[[nodiscard]] Result<void, std::string> add_way_in_from_above(PickPlaceJob& job, const Grasp& grasp,
                                                              double height_m,
                                                              const JobOptions& options) noexcept;

/// @brief Gives @p job a way out from above: from the arm's joints @p now (where it stands when the
/// job starts), the hand first rises @p height_m along the table's normal, then goes to the
/// initial pose; for when the direct way to the initial pose passes another object (the last job
/// left the hand low beside the object it placed). @return the IK error of the risen pose.
[[nodiscard]] Result<void, std::string> add_rise_first(PickPlaceJob& job,
                                                       const drivers::jaco::JointAngles& now,
                                                       double height_m,
                                                       const JobOptions& options) noexcept;

/// @brief Gives @p job (made from @p grasp) a way round: the carry first goes to a way-point at the
/// carry height, beside the middle of the carry's line by @p side_m along the table (positive to
/// the left of the way from the lift to above the place, seen from above), then on to above the
/// place; for when the direct carry passes another object and no higher lift is in reach.
/// @return the IK error of the way-point, or a carry too short to have a side.
[[nodiscard]] Result<void, std::string> add_way_round(PickPlaceJob& job, const Grasp& grasp,
                                                      double side_m,
                                                      const JobOptions& options) noexcept;

/// @brief How far a straight move of a job may stray from its line (check_job_paths).
inline constexpr double MAX_SWING_M = 0.03;

/// @brief Checks every move the manager will send for @p job, from the arm's joints @p now (to the
/// initial pose, the pre-grasp, the grasp, then lift, carry, place and retreat), each along its
/// joint-space path: the tool keeps @p clearance_m from every sphere of @p others
/// (joint_path_blocked) and stays inside the driver's safety limits (drivers::jaco::
/// check_joint_move, the check that would otherwise refuse the command mid-job); the straight moves
/// near the objects (approach, lift, place, retreat) stray at most MAX_SWING_M from their straight
/// line (joint_path_deviation: else the IK chose another branch). @p others: the objects other
/// than the target. @return the first move that fails and why, e.g. "carry: passes another
/// object". @note Allocates only for the error text (planning, not the frame path).
[[nodiscard]] Result<void, std::string> check_job_paths(const PickPlaceJob& job,
                                                        const drivers::jaco::JointAngles& now,
                                                        std::span<const Obstacle> others,
                                                        double clearance_m,
                                                        const drivers::jaco::SafetyLimits& limits);

/// @brief Most spheres cover_box gives one box.
inline constexpr std::size_t MAX_BOX_SPHERES = 64;
/// @brief @p box as obstacles for the execution manager: cut into at most 4 x 4 x 4 cells about a
/// quarter of its largest extent (at least 3 cm) wide, each covered by its circumscribed sphere, so
/// a plate or a tall box is a set of small spheres rather than one sphere as wide as it is.
/// @return the spheres written to @p out (at most MAX_BOX_SPHERES, fewer if @p out is shorter).
/// @pre finite box. No allocation.
std::size_t cover_box(const ObjectBox& box, std::span<Obstacle> out) noexcept;

/// @brief Finger value for an opening of @p opening_m (0 open at max_opening_m, closed at 0).
[[nodiscard]] double finger_for_opening(double opening_m, const JobOptions& options) noexcept;
/// @brief The opening (m) of finger value @p finger: the inverse of finger_for_opening.
[[nodiscard]] double opening_for_finger(double finger, const JobOptions& options) noexcept;

}  // namespace orthoflow::manipulation
