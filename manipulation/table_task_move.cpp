// The table-task runner's next move (manipulation/table_task_runner.hpp): parking the arm when the
// object is unseen or hidden, then the search for a pick-and-place job that keeps clear of the
// other objects (grasps x lifts x spots x ways in, out and round). Its life cycle is in
// table_task_runner.cpp, its view of the table in table_task_view.cpp.
#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_safety.hpp"
#include "manipulation/grasp_planner.hpp"
#include "manipulation/table_task_limits.hpp"
#include "manipulation/table_task_runner.hpp"

namespace orthoflow::manipulation {

namespace jaco = drivers::jaco;
using Eigen::Vector3d;

bool TableTaskRunner::park(const jaco::ArmSnapshot& arm, const Submit& submit) {
  if (arm.control != jaco::ControlState::IDLE) return parking_;
  parking_ = false;
  if (jaco::max_joint_error(options_.job.initial, arm.joints) <=
      options_.limits.joint_tolerance_deg)
    return false;
  std::size_t used = 0;  // every object is an obstacle here: no target yet
  for (const SeenObject& o : seen_) used = add_spheres(o, used);
  if (joint_path_blocked(arm.joints, options_.job.initial, std::span(others_).first(used),
                         options_.limits.obstacle_clearance_m))
    return false;
  jaco::ArmCommand c;
  c.kind = jaco::ArmCommand::Kind::MOVE_JOINTS;
  c.joints = options_.job.initial;
  parking_ = submit(c);  // refused (a fault): nothing moves
  return parking_;
}

void TableTaskRunner::start_move(std::int64_t now_ns, const jaco::ArmSnapshot& arm,
                                 const Submit& submit) {
  MoveRecord& r = moves_[move_];
  const SeenObject* s = find_seen(r.track, planned_[move_], {}, 0.0, 0.06);
  // A track's label flickers to Unknown in some frames (the tracker's fragments); another label is
  // another object.
  if (s != nullptr && !s->label.empty() && s->label != r.label) s = nullptr;
  // Seen behind the arm, its centre is not where it is (a cut view).
  const bool cut = s != nullptr && arm_hides(s->centre, 0.5 * s->box.extents.head<2>().norm());
  if (s == nullptr || cut) {
    // The arm, where the last job left it, may hide it from the camera: it goes to the initial pose
    // first. Then the tracker may be re-forming its track: look again for a while.
    if (park(arm, submit)) {
      waiting_ = true;
      return;
    }
    if (++unseen_frames_ < options_.look_again_frames) {
      waiting_ = true;
      return;
    }
  }
  if (s == nullptr) {
    r.failure = "the object is no longer seen";
    unseen_frames_ = 0;
    ++move_;
    return;
  }
  unseen_frames_ = 0;
  JobOptions job_options = options_.job;
  GraspOptions& g = job_options.grasp;
  g.seed = arm.joints;
  const auto plan = plan_grasp(s->box, g);
  if (!plan.has_value()) {
    r.failure = std::string("no grasp: ") + to_string(plan.error());
    ++move_;
    return;
  }
  if (plan->best() == nullptr) {
    r.failure = "no feasible grasp";
    if (plan->rejected_count > 0)
      r.failure += std::string(": ") + to_string(plan->rejected[0].reason);
    ++move_;
    return;
  }
  target_track_ = s->track;
  target_centre_ = s->centre;
  target_label_ = r.label;
  bystander_count_ = 0;
  for (const SeenObject& o : seen_) {
    if (o.track != target_track_ && (o.centre - s->centre).norm() > 0.03 &&
        bystander_count_ < bystanders_.size())
      bystanders_[bystander_count_++] = o.centre;
  }
  const SeenObject* target = current_target();
  const Vector3d tool = jaco::forward_kinematics(options_.job.initial).translation();
  const auto obstacles =
      std::span<const Obstacle>(others_).first(fill_obstacles(target, tool, false));
  // Carry high enough that the hand passes 10 cm above the tallest other object (0.15-0.30 m).
  const SupportPlane& table = options_.job.grasp.table;
  double tallest = 0.0;
  for (const SeenObject& o : seen_) {
    if (!is_target(o, target))
      tallest = std::max(tallest, table.height_of(o.centre) + 0.5 * o.box.extents.z());
  }
  const double wanted = std::clamp(tallest + 0.10 - table.height_of(s->centre), 0.15, 0.30);
  // Other lifts when that one's job is blocked or out of reach: higher to pass over, lower to
  // reach.
  std::array<double, 5> lifts{wanted, wanted + 0.05, wanted + 0.10, wanted - 0.05, LOWEST_LIFT_M};
  const auto lifts_end = std::unique(
      lifts.begin(),
      std::remove_if(lifts.begin(), lifts.end(), [](double l) { return l < LOWEST_LIFT_M; }));
  const double clear = options_.limits.obstacle_clearance_m;
  std::optional<PickPlaceJob> job;
  std::string why;  // why the preferred job (own spot, best grasp, first lift) is not the one
  // The move's own spot first; then the spots of the moves still to come (a spot the arm cannot
  // reach with this object may suit another one: they swap). At each, the jobs of every grasp (best
  // first) and lift, solved once; the first whose every move keeps clear of the other objects
  // along its joint-space path and inside the safety limits, with a margin first (a perceived box
  // shifts by a centimetre or two between frames, and the manager checks every frame), then
  // without.
  // When no job at any spot is clear, the same search again with a way in from above (the hand
  // rises over what is in the way, then comes down to the pre-grasp), 10 then 20 cm; then with a
  // way out from above as well (the hand first rises from where the last job left it); then with a
  // way round (the carry passes beside the middle of its line, 12 then 24 cm to either side).
  struct Way {
    double above, rise, aside;
  };
  constexpr std::array<Way, 10> WAYS{{{0.0, 0.0, 0.0},
                                      {0.10, 0.0, 0.0},
                                      {0.20, 0.0, 0.0},
                                      {0.0, 0.15, 0.0},
                                      {0.10, 0.15, 0.0},
                                      {0.20, 0.15, 0.0},
                                      {0.0, 0.0, 0.12},
                                      {0.0, 0.0, -0.12},
                                      {0.0, 0.0, 0.24},
                                      {0.0, 0.0, -0.24}}};
  std::vector<std::pair<PickPlaceJob, const Grasp*>> made;
  std::size_t spot = move_;
  for (const auto& [above, rise, aside] : WAYS) {
    for (spot = move_; spot < moves_.size() && !job; ++spot) {
      if (spot != move_ && !spots_swap(move_, spot)) continue;
      const Vector3d place(moves_[spot].to.x(), moves_[spot].to.y(), s->centre.z());
      made.clear();
      for (std::size_t k = 0; k < plan->feasible_count; ++k) {
        for (auto l = lifts.begin(); l != lifts_end; ++l) {
          job_options.lift_m = *l;
          auto m = make_pick_place_job(s->track, s->centre, plan->feasible[k], place, job_options);
          const bool ways =
              m &&
              (above == 0.0 || add_way_in_from_above(*m, plan->feasible[k], above, job_options)) &&
              (rise == 0.0 || add_rise_first(*m, arm.joints, rise, job_options)) &&
              (aside == 0.0 || add_way_round(*m, plan->feasible[k], aside, job_options));
          if (ways)
            made.emplace_back(*m, &plan->feasible[k]);
          else if (!m && spot == move_ && k == 0 && l == lifts.begin() && above == 0.0 &&
                   rise == 0.0 && aside == 0.0)
            why = "no job: " + m.error();
        }
      }
      for (const double margin : {PLAN_MARGIN_M, 0.0}) {
        for (const auto& [candidate, grasp] : made) {
          auto ok = check_job_paths(candidate, arm.joints, obstacles, clear + margin,
                                    jaco::SafetyLimits{});
          if (ok) {
            job = candidate;
            r.grasp = to_string(grasp->kind);
            if (above > 0.0) r.grasp += " from above";
            if (rise > 0.0) r.grasp += ", rising first";
            if (aside != 0.0) r.grasp += ", carried round";
            break;
          }
          if (why.empty() && margin == 0.0) why = "no clear job: " + ok.error();
        }
        if (job) break;
      }
    }
    if (job) break;
  }
  if (job && spot - 1 != move_) std::swap(r.to, moves_[spot - 1].to);
  target_place_ = r.to;
  if (!job) {
    r.failure = why;
    ++move_;
    return;
  }
  held_ = held_object(jaco::forward_kinematics(job->grasp).translation(), s->centre, s->box.extents,
                      table.normal);
  if (on_move_started) on_move_started(move_, *s);
  move_start_ns_ = now_ns;
  (void)manager_.start(*job, now_ns);
  state_ = State::RUNNING;
}

}  // namespace orthoflow::manipulation
