#include "manipulation/table_task_runner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include "drivers/jaco_kinematics.hpp"
#include "drivers/jaco_safety.hpp"
#include "manipulation/grasp_planner.hpp"

namespace orthoflow::manipulation {

namespace jaco = drivers::jaco;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

/// Perceived objects this near the tool are cut by the hand's own body filter.
constexpr double HAND_HIDES_M = 0.17;
/// Planned paths keep this much more than the manager's clearance when they can.
constexpr double PLAN_MARGIN_M = 0.02;
/// The lowest lift a job is planned with (the grasp check wants the object half of it up).
constexpr double LOWEST_LIFT_M = 0.10;
/// From the place on, an object this near the move's spot is the target, put down.
constexpr double PLACED_NEAR_M = 0.06;
/// After a move, its object seen this near (along the table) to where it was planned from was left
/// behind.
constexpr double LEFT_BEHIND_M = 0.04;

}  // namespace

const char* to_string(TableTaskKind task) noexcept {
  return task == TableTaskKind::CLEAR_TABLE ? "clear_table" : "serve_a_meal";
}

bool parse_table_task(const std::string& name, TableTaskKind& out) noexcept {
  if (name == "clear_table" || name == "clear-table") {
    out = TableTaskKind::CLEAR_TABLE;
    return true;
  }
  if (name == "serve_a_meal" || name == "serve-a-meal") {
    out = TableTaskKind::SERVE_A_MEAL;
    return true;
  }
  return false;
}

TableTaskRunner::TableTaskRunner(TableTaskOptions options)
    : options_(std::move(options)),
      camera_from_base_(options_.base_from_camera.inverse()),
      others_(MAX_TASK_OBJECTS * MAX_BOX_SPHERES),
      manager_(options_.limits) {}

void TableTaskRunner::on_objects(std::span<const SeenObject> objects, std::int64_t stamp_ns) {
  seen_.assign(objects.begin(), objects.end());
  seen_stamp_ns_ = stamp_ns;
}

void TableTaskRunner::on_arm_pose(const jaco::JointAngles& joints) noexcept {
  // The arm as the body filter cuts it: the link model, with its margin.
  ArmBodyModel body;
  body.margin_m = 0.0;
  std::array<kernels::Capsule, ARM_BODY_CAPSULES> bare{};
  const std::size_t n =
      arm_body_capsules(joints, options_.base_from_camera, body, jaco::jaco2_geometry(), bare);
  on_arm_body(std::span(bare).first(n));
}

void TableTaskRunner::on_arm_body(std::span<const kernels::Capsule> body) noexcept {
  sight_count_ = std::min(body.size(), sight_.size());
  for (std::size_t i = 0; i < sight_count_; ++i) {
    sight_[i] = body[i];
    sight_[i].radius += static_cast<float>(ArmBodyModel{}.margin_m);
  }
}

Result<void, std::string> TableTaskRunner::start(std::span<const std::string> known) {
  if (state_ != State::IDLE) return err(std::string("the task has already started"));
  if (options_.task == TableTaskKind::SERVE_A_MEAL) {
    for (const std::string& want : options_.bring) {
      if (std::find(known.begin(), known.end(), want) == known.end())
        return err("nobody taught the category '" + want + "'");
    }
  }
  std::vector<TableObject> objects;
  for (const SeenObject& s : seen_)
    objects.push_back({s.track, s.label, s.centre, footprint_radius(s.box.extents)});
  TaskPlan plan;
  if (options_.task == TableTaskKind::CLEAR_TABLE) {
    ClearTableOptions o;
    o.area = options_.area;
    o.table_items = options_.keep;
    plan = plan_clear_table(objects, o);
  } else {
    ServeOptions o;
    o.categories = options_.bring;
    o.user_place = options_.user_place;
    plan = plan_serve_a_meal(objects, o);
  }
  for (const TaskStay& s : plan.stays) stays_.push_back({s.track, s.label, to_string(s.reason)});
  for (const TaskMove& m : plan.moves) {
    const auto it = std::find_if(seen_.begin(), seen_.end(),
                                 [&](const SeenObject& x) { return x.track == m.track; });
    MoveRecord r;
    r.track = m.track;
    r.label = m.label;
    r.to = m.place;
    moves_.push_back(std::move(r));
    planned_.push_back(it->centre);
    radii_.push_back(m.radius_m);
  }
  occupied_ = std::move(plan.occupied);
  packed_ = plan.packed;
  packed_gap_m_ = plan.gap_m;
  state_ = State::MOVING;
  return {};
}

void TableTaskRunner::step(std::int64_t now_ns, const jaco::ArmSnapshot& arm,
                           const Submit& submit) {
  if (state_ != State::MOVING) return;
  waiting_ = false;
  while (state_ == State::MOVING && !waiting_ &&
         (move_ < moves_.size() || (options_.retry_failed && !retried_ && add_retries() > 0)))
    start_move(now_ns, arm, submit);
  if (state_ == State::MOVING && !waiting_) state_ = State::FINISHED;
}

std::size_t TableTaskRunner::fill_obstacles(const SeenObject* target, const Vector3d& hand,
                                            bool holding) {
  std::size_t used = 0;
  for (const SeenObject& o : seen_) {
    if (!is_target(o, target) && !(holding && (o.centre - hand).norm() < HAND_HIDES_M))
      used = add_spheres(o, used);
  }
  return used;
}

const SeenObject* TableTaskRunner::find_seen(std::uint32_t track, const Vector3d& near,
                                             const std::string& label, double same_label_m,
                                             double any_m, bool not_bystanders) const {
  const SeenObject* best = nullptr;
  double best_d = 0.0;
  bool by_track = false;
  for (const SeenObject& o : seen_) {
    if (not_bystanders && a_bystander(o.centre)) continue;
    const double d = (o.centre - near).norm();
    // By its track first (of the pieces with it, the nearest); else by distance.
    if (o.track == track) {
      if (!by_track || d < best_d) {
        best = &o;
        best_d = d;
      }
      by_track = true;
    } else if (!by_track && (d < any_m || (d < same_label_m && o.label == label)) &&
               (best == nullptr || d < best_d)) {
      best = &o;
      best_d = d;
    }
  }
  return best;
}

bool TableTaskRunner::a_bystander(const Vector3d& centre) const noexcept {
  // Standing (not risen with the hand) and nearer to where another object stood when the move
  // started than to where the target stood: that other object, whatever its track or label.
  const Vector3d& up = options_.job.grasp.table.normal;
  if ((centre - target_centre_).dot(up) > options_.limits.target_moved_m) return false;
  const double to_target = (centre - target_centre_).norm();
  for (std::size_t k = 0; k < bystander_count_; ++k) {
    if ((centre - bystanders_[k]).norm() < to_target) return true;
  }
  return false;
}

const SeenObject* TableTaskRunner::current_target() const {
  // Its track; else (renumbered, or moved by someone) the nearest object of its label within 15 cm
  // of where it was planned, or anything within 3 cm; never one of the move's bystanders (two cans
  // side by side: when the hand has lifted one out of view, the other one is not it).
  return find_seen(target_track_, target_centre_, target_label_, 0.15, 0.03, true);
}

bool TableTaskRunner::is_target(const SeenObject& o, const SeenObject* t) const {
  // The target (current_target(), found once per use) or a piece of it (the tracker's fragments
  // near it): never an obstacle.
  return &o == t || o.track == target_track_ || (o.centre - target_centre_).norm() < 0.03 ||
         (t != nullptr && (o.centre - t->centre).norm() < 0.03) ||
         (placing() && (o.centre.head<2>() - target_place_).norm() < PLACED_NEAR_M);
}

bool TableTaskRunner::placing() const noexcept {
  // From the place on the target stands at its spot (under a new track: the hand hid it).
  const Phase p = manager_.phase();
  return state_ == State::RUNNING &&
         (p == Phase::PLACE || p == Phase::RELEASE || p == Phase::RETREAT);
}

bool TableTaskRunner::arm_hides(const Vector3d& base_point, double radius_m) const noexcept {
  return occludes(std::span(sight_).first(sight_count_), Vector3d::Zero(),
                  camera_from_base_ * base_point, radius_m);
}

bool TableTaskRunner::spots_swap(std::size_t a, std::size_t b) const {
  if (!packed_) return true;  // the grid's spots (or the user's places): room for any object
  const Vector2d at_a = moves_[a].to, at_b = moves_[b].to;
  std::vector<Footprint> others = occupied_;
  for (std::size_t k = 0; k < moves_.size(); ++k)  // every other place given (a retry repeats one)
    if (moves_[k].to != at_a && moves_[k].to != at_b) others.push_back({moves_[k].to, radii_[k]});
  const Footprint a_at_b{at_b, radii_[a]}, b_at_a{at_a, radii_[b]};
  others.push_back(b_at_a);
  if (!fits_in_area(options_.area, a_at_b, others, packed_gap_m_)) return false;
  others.back() = a_at_b;
  return fits_in_area(options_.area, b_at_a, others, packed_gap_m_);
}

std::size_t TableTaskRunner::add_spheres(const SeenObject& o, std::size_t used) {
  if (used + MAX_BOX_SPHERES > others_.size()) return used;
  return used + cover_box(o.box, std::span(others_).subspan(used, MAX_BOX_SPHERES));
}

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

bool TableTaskRunner::cycle(std::int64_t now_ns, const jaco::ArmSnapshot& arm,
                            const Submit& submit) {
  if (state_ == State::RUNNING && manager_.running()) {
    PerceptionInput in;
    in.stamp_ns = seen_stamp_ns_;
    const Vector3d tool_base = jaco::forward_kinematics(arm.joints).translation();
    const bool holding = manager_.holding();
    // The hand's own filter cuts a target it is about to take, and the arm between the camera and
    // the target cuts its view: such a view is not evidence of where it is.
    const double radius = held_.radius_m;  // the target's footprint
    const SeenObject* t = current_target();
    const bool cut = t != nullptr && arm_hides(t->centre, radius);
    if (t != nullptr && (t->centre - tool_base).norm() > HAND_HIDES_M && !cut) {
      in.target_seen = true;
      in.target_centre = t->centre;
    }
    in.target_hidden =
        !in.target_seen && (cut || (target_centre_ - tool_base).norm() < HAND_HIDES_M ||
                            arm_hides(target_centre_, radius));
    in.others = std::span(others_).first(fill_obstacles(t, tool_base, holding));
    was_holding_ = manager_.holding();
    const ArmRequest r = manager_.step(now_ns, arm_input(arm), in);
    if (r.kind != ArmRequest::Kind::NONE && !submit(arm_command(r))) manager_.refused(now_ns);
  }
  return manager_.running() || parking_;
}

void TableTaskRunner::finish_step(std::int64_t now_ns) {
  if (state_ == State::RUNNING && !manager_.running()) finish_move(now_ns);
}

void TableTaskRunner::finish_move(std::int64_t now_ns) {
  MoveRecord& r = moves_[move_];
  r.seconds = 1e-9 * static_cast<double>(now_ns - move_start_ns_);
  std::array<Decision, ExecutionManager::LOG_SIZE> log{};
  const std::size_t n = manager_.decisions(log);
  for (std::size_t i = 0; i < n; ++i) {
    // An operator lasts until the next phase change (a note within a phase is not one).
    std::size_t next = i + 1;
    while (next < n && log[next].from == log[next].to) ++next;
    const std::int64_t end = next < n ? log[next].stamp_ns : now_ns;
    if (log[i].from != log[i].to && log[i].to != Phase::DONE && log[i].to != Phase::ABORTED)
      r.operators.push_back(
          {to_string(log[i].to), 1e-9 * static_cast<double>(end - log[i].stamp_ns)});
    char line[160];
    std::snprintf(line, sizeof line, "%.2f s %s -> %s: %s",
                  1e-9 * static_cast<double>(log[i].stamp_ns - move_start_ns_),
                  to_string(log[i].from), to_string(log[i].to), log[i].why);
    r.decisions.emplace_back(line);
  }
  r.done = manager_.phase() == Phase::DONE;
  if (!r.done) r.failure = to_string(manager_.abort_reason());
  if (r.done) check_left_behind(move_);
  if (on_move_ended) on_move_ended(move_);
  const AbortReason why = manager_.abort_reason();
  ++move_;
  if (stop_requested_) {
    end_task(stopped_);
    return;
  }
  if (why == AbortReason::ARM_FAULT || why == AbortReason::ARM_ESTOP ||
      why == AbortReason::REFUSED || (!r.done && was_holding_)) {
    end_task(std::string("move ") + std::to_string(move_) + " ended with " + to_string(why) +
             (was_holding_ ? " while holding the object" : "") + ": the task stops");
    return;
  }
  state_ = State::MOVING;
}

void TableTaskRunner::check_left_behind(std::size_t move) {
  MoveRecord& r = moves_[move];
  const Vector3d& from = planned_[move];
  const SupportPlane& table = options_.job.grasp.table;
  const auto along_table = [&](const Vector3d& d) {
    return (d - d.dot(table.normal) * table.normal).norm();
  };
  bool at_spot = false, left = false;
  for (const SeenObject& o : seen_) {
    if ((o.centre.head<2>() - r.to).norm() < PLACED_NEAR_M) at_spot = true;
    if ((o.label == r.label || o.track == r.track) &&
        along_table(o.centre - from) < LEFT_BEHIND_M && !a_bystander(o.centre) &&
        !arm_hides(o.centre, 0.5 * o.box.extents.head<2>().norm()))
      left = true;
  }
  if (left && !at_spot) {
    r.done = false;
    r.failure = "left behind: the object still stands where it was";
  }
}

std::size_t TableTaskRunner::add_retries() {
  retried_ = true;
  const std::size_t first_pass = moves_.size();
  for (std::size_t k = 0; k < first_pass; ++k) {
    if (moves_[k].done) continue;
    MoveRecord r;
    r.track = moves_[k].track;
    r.label = moves_[k].label;
    r.to = moves_[k].to;
    r.attempt = 2;
    r.retry_of = k;
    moves_.push_back(std::move(r));
    planned_.push_back(planned_[k]);
    radii_.push_back(radii_[k]);
  }
  return moves_.size() - first_pass;
}

void TableTaskRunner::end_task(const std::string& why) {
  stopped_ = why;
  for (std::size_t k = move_; k < moves_.size(); ++k)
    moves_[k].failure = "not started: the task stopped";
  state_ = State::FINISHED;
}

void TableTaskRunner::request_stop(std::int64_t now_ns, const std::string& why,
                                   const Submit& submit) {
  if (state_ == State::FINISHED || stop_requested_) return;
  stop_requested_ = true;
  stopped_ = why;
  if (state_ == State::RUNNING) {
    manager_.request_stop(now_ns);  // finish_step() ends the move, then the task
    return;
  }
  if (parking_) {
    jaco::ArmCommand c;
    c.kind = jaco::ArmCommand::Kind::STOP;
    (void)submit(c);
    parking_ = false;
  }
  end_task(why);
}

void TableTaskRunner::halt(std::int64_t now_ns) noexcept {
  if (manager_.running()) manager_.request_stop(now_ns);
}

bool TableTaskRunner::held(HeldObject& out) const noexcept {
  if (state_ != State::RUNNING || !manager_.holding()) return false;
  out = held_;
  return true;
}

}  // namespace orthoflow::manipulation
