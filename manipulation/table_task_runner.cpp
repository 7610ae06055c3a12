// The table-task runner's life cycle (manipulation/table_task_runner.hpp): the task planned, a move
// started each frame, the running job fed every arm cycle, each move ended and recorded (retries,
// objects left behind), and the task stopped. Its view of the table is in table_task_view.cpp, the
// search for each move's job in table_task_move.cpp.
#include "manipulation/table_task_runner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_safety.hpp"
#include "manipulation/grasp_planner.hpp"
#include "manipulation/table_task_limits.hpp"

namespace orthoflow::manipulation {

namespace jaco = drivers::jaco;
using Eigen::Vector2d;
using Eigen::Vector3d;

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
