#include "graphs/table_task_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "drivers/jaco_controller.hpp"
#include "drivers/jaco_link.hpp"
#include "engine/engine.hpp"
#include "graphs/arm_state_feed.hpp"
#include "graphs/body_filter_node.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/learning_service.hpp"
#include "graphs/objects_output.hpp"
#include "graphs/session_log.hpp"
#include "graphs/tabletop.hpp"
#include "graphs/world_source.hpp"
#include "manipulation/arm_body.hpp"
#include "manipulation/grasp_planner.hpp"
#include "manipulation/pick_place_job.hpp"
#include "simulation/sim_jaco_transport.hpp"
#include "simulation/table_world.hpp"

namespace orthoflow::graphs {

namespace jaco = drivers::jaco;
using Eigen::Isometry3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using manipulation::Phase;

const char* to_string(TableTask task) noexcept {
  return task == TableTask::CLEAR_TABLE ? "clear_table" : "serve_a_meal";
}

const char* to_string(TaskEvent event) noexcept {
  switch (event) {
    case TaskEvent::MOVE_TARGET:
      return "move-target";
    case TaskEvent::STOP_PERCEPTION:
      return "stop-perception";
    case TaskEvent::UNPLUG_ARM:
      return "unplug-arm";
    default:
      return "none";
  }
}

manipulation::ExecutionLimits TableTaskConfig::default_limits() noexcept {
  manipulation::ExecutionLimits limits;
  limits.target_lost_ns = 5'000'000'000;
  for (const Phase p : {Phase::APPROACH, Phase::LIFT, Phase::PLACE, Phase::RETREAT})
    limits.timeout_ns[static_cast<std::size_t>(p)] = 20'000'000'000;
  limits.obstacle_clearance_m = 0.02;
  limits.target_moved_m = 0.06;
  return limits;
}

std::size_t TableTaskReport::arrived() const noexcept {
  return static_cast<std::size_t>(
      std::count_if(moves.begin(), moves.end(), [](const MoveReport& m) { return m.arrived; }));
}

Isometry3d synthetic_base_from_camera(const simulation::TableSpec& table) {
  const simulation::TableFrame t = simulation::table_frame(table);
  constexpr double BASE_BEYOND_CENTRE_M = 0.28284271247461906;  // 0.98995 - 0.70711 (the yaml)
  const auto v = [](const simulation::Vec3& a) { return Vector3d(a[0], a[1], a[2]); };
  Isometry3d camera_from_base = Isometry3d::Identity();
  const Vector3d z = v(t.normal), y = v(t.forward);
  camera_from_base.linear().col(0) = y.cross(z);
  camera_from_base.linear().col(1) = y;
  camera_from_base.linear().col(2) = z;
  camera_from_base.translation() = v(t.point(0.0, BASE_BEYOND_CENTRE_M));
  return camera_from_base.inverse();
}

namespace {

constexpr std::int64_t START_NS = 1'000'000'000;  // frame stamps must not be 0
constexpr double ARRIVED_M = 0.05;
/// Perceived objects this near the tool are cut by the hand's own body filter.
constexpr double HAND_HIDES_M = 0.17;
/// Planned paths keep this much more than the manager's clearance when they can.
constexpr double PLAN_MARGIN_M = 0.02;
/// The lowest lift a job is planned with (the grasp check wants the object half of it up).
constexpr double LOWEST_LIFT_M = 0.10;
/// From the place on, an object this near the move's spot is the target, put down.
constexpr double PLACED_NEAR_M = 0.06;

std::vector<simulation::Category> default_categories() {
  using simulation::Category;
  return {Category::BOTTLE, Category::MUG, Category::CAN, Category::FLASK, Category::PLATE};
}

/// One perceived object in the arm's base frame.
struct Seen {
  std::uint32_t track = 0;
  std::string label;
  manipulation::ObjectBox box;
  Vector3d centre = Vector3d::Zero();
};

class Session final : public WorldFeed {
 public:
  explicit Session(const TableTaskConfig& config) : config_(config) {}

  Result<TableTaskReport, std::string> run();
  const simulation::Scene* next_frame(kernels::PointCloud& cloud) noexcept override;

 private:
  enum class Stage { SETTLE, TEACH, RECOGNISE, MOVE, RUNNING, FINISH, END };

  Result<void, std::string> build_world();
  /// The seeded table: make_scene's objects on the robot frames' table, clear of the arm's base
  /// column and of the placing area / the user's place, up to config_.objects.
  [[nodiscard]] simulation::Scene draw_scene(std::uint64_t seed);
  Result<void, std::string> open_arm();
  void take_objects() noexcept;
  void advance_stage();
  void teach();
  void plan_task();
  void start_move();
  void finish_move();
  /// Sends the arm to the initial pose if it is elsewhere and idle (it may hide the next object).
  /// @return true while it is on its way.
  bool park();
  void arm_cycle() noexcept;
  void fire_event();
  /// Writes every object's spheres into others_ but the target's (@p target: current_target())
  /// (and, @p holding, those near
  /// @p hand: pieces of the object in it). @return how many.
  std::size_t fill_obstacles(const Seen* target, const Vector3d& hand, bool holding);
  /// The target in the newest objects: its track; else (renumbered, or moved by someone) the
  /// nearest object of its label within 15 cm of where it was planned, or anything within 3 cm.
  [[nodiscard]] const Seen* current_target() const {
    return find_seen(target_track_, target_centre_, target_label_, 0.15, 0.03);
  }
  /// The target @p t (current_target(), found once per use) or a piece of it (the tracker's
  /// fragments near it): never an obstacle.
  [[nodiscard]] bool is_target(const Seen& o, const Seen* t) const {
    return &o == t || o.track == target_track_ || (o.centre - target_centre_).norm() < 0.03 ||
           (t != nullptr && (o.centre - t->centre).norm() < 0.03) ||
           (placing() && (o.centre.head<2>() - target_place_).norm() < PLACED_NEAR_M);
  }
  /// True from the place on: the target stands at its spot (under a new track: the hand hid it).
  [[nodiscard]] bool placing() const noexcept {
    const Phase p = manager_.phase();
    return stage_ == Stage::RUNNING &&
           (p == Phase::PLACE || p == Phase::RELEASE || p == Phase::RETREAT);
  }
  /// True if the arm, at the newest frame, stands between the camera and a @p radius_m object at
  /// @p base_point.
  [[nodiscard]] bool arm_hides(const Vector3d& base_point, double radius_m) const noexcept {
    return manipulation::occludes(std::span(sight_).first(sight_count_), Vector3d::Zero(),
                                  camera_from_base_ * base_point, radius_m);
  }
  /// The object of @p track in the newest objects; else (the tracker renumbered it, or someone
  /// moved it) the nearest one to @p near: of @p label within @p same_label_m, or any within
  /// @p any_m.
  [[nodiscard]] const Seen* find_seen(std::uint32_t track, const Vector3d& near,
                                      const std::string& label, double same_label_m,
                                      double any_m) const;
  /// Adds @p o's spheres to others_ after the first @p used. @return the new count.
  std::size_t add_spheres(const Seen& o, std::size_t used);
  [[nodiscard]] std::string truth_near(const Vector3d& base_point) const;
  [[nodiscard]] std::int64_t now() const noexcept { return sim_.clock().now_ns(); }
  [[nodiscard]] Vector3d to_base(const simulation::Vec3& p) const {
    return base_from_camera_ * Vector3d(p[0], p[1], p[2]);
  }

  TableTaskConfig config_;
  TableTaskReport report_;
  Isometry3d base_from_camera_ = Isometry3d::Identity();
  std::optional<simulation::TableWorld> world_;
  simulation::SimJacoTransport sim_;
  std::unique_ptr<jaco::JacoController> arm_;
  std::int64_t next_cycle_ns_ = 0;
  ArmStateChannel arm_states_;
  std::unique_ptr<LearningService> learning_;
  std::unique_ptr<LearningClient> teacher_;
  ObjectsHub hub_;
  std::unique_ptr<ObjectsSubscription> objects_;
  engine::ObjectListPayload list_{};
  std::vector<Seen> seen_;
  std::int64_t seen_stamp_ns_ = 0;
  // Every other object's spheres (engine::OBJECT_LIST_CAPACITY objects at most).
  std::vector<manipulation::Obstacle> others_ = std::vector<manipulation::Obstacle>(
      engine::OBJECT_LIST_CAPACITY * manipulation::MAX_BOX_SPHERES);
  core::Rng rng_{0};
  simulation::RenderOptions render_{};
  manipulation::JobOptions job_options_{};
  manipulation::ExecutionManager manager_{};
  Stage stage_ = Stage::SETTLE;
  std::uint64_t frame_ = 0;
  std::uint64_t stage_frame_ = 0;
  std::size_t teaches_sent_ = 0, acks_ = 0;
  manipulation::TaskPlan plan_;
  std::size_t move_ = 0;
  std::int64_t move_start_ns_ = 0;
  int target_object_ = -1;  // world object id of the current move's target
  std::uint32_t target_track_ = 0;
  Vector3d target_centre_ = Vector3d::Zero();
  Vector3d target_start_ = Vector3d::Zero();  // the world's object centre at the move's start
  Vector2d target_place_ = Vector2d::Zero();  // where the current move puts it (base x, y)
  std::string target_label_;
  std::vector<Vector3d> planned_;  // each move's object centre at planning time
  Isometry3d camera_from_base_ = Isometry3d::Identity();
  bool event_fired_ = false, perception_dead_ = false;
  manipulation::HeldObject held_;  // the target as the hand will hold it
  bool was_holding_ = false;       // the manager held the object at its last step
  bool parking_ = false;           // the arm is on its way to the initial pose between jobs
  bool waiting_ = false;           // the next move waits for its object to be seen again
  std::uint32_t unseen_frames_ = 0;
  std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES> capsules_{};
  // The arm at the newest frame, as the body filter cuts it (with its margin), for occlusion.
  std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES> sight_{};
  std::size_t sight_count_ = 0;
};

simulation::Scene Session::draw_scene(std::uint64_t seed) {
  simulation::SceneConfig scene_config;
  scene_config.objects =
      std::min<std::uint32_t>(config_.objects + 6, simulation::MAX_SCENE_OBJECTS);
  scene_config.categories = config_.categories.empty() ? default_categories() : config_.categories;
  simulation::Scene scene = simulation::make_scene(scene_config, seed);
  scene.table = simulation::TableSpec{};  // the table the robot frames assume
  base_from_camera_ = synthetic_base_from_camera(scene.table);
  const simulation::TableFrame frame = simulation::table_frame(scene.table);
  // Keep the objects that stand on this table, clear of the arm's base column, up to the count.
  std::vector<simulation::PlacedObject> kept;
  for (const simulation::PlacedObject& o : scene.objects) {
    const double r = o.model.footprint_radius;
    const bool on_table = std::fabs(o.table_x) + r < 0.5 * scene.table.width_m - 0.02 &&
                          std::fabs(o.table_y) + r < 0.5 * scene.table.depth_m - 0.02;
    const Vector2d at = to_base(frame.point(o.table_x, o.table_y)).head<2>();
    // The placing area and the user's place start empty (a tray, a place setting).
    const Vector2d margin(r + 0.02, r + 0.02);
    const manipulation::TableArea area{config_.area.min - margin, config_.area.max + margin};
    bool free = true;
    if (config_.task == TableTask::CLEAR_TABLE) {
      free = !area.contains(at);
    } else {
      for (std::size_t k = 0; k < std::max<std::size_t>(config_.bring.size(), 1); ++k)
        free =
            free && (at - config_.user_place - Vector2d(0.15 * double(k), 0.0)).norm() > r + 0.08;
    }
    if (on_table && free && at.norm() > 0.30 && kept.size() < config_.objects) kept.push_back(o);
  }
  scene.objects = std::move(kept);
  return scene;
}

Result<void, std::string> Session::build_world() {
  // serve_a_meal: the scene is drawn again (seed + 1000 k, at most 50 times) until it holds every
  // category asked for, so that the task has something to serve (none does: the first draw).
  simulation::Scene scene = draw_scene(config_.seed);
  for (std::uint64_t draw = 0; draw < 50 && config_.task == TableTask::SERVE_A_MEAL; ++draw) {
    simulation::Scene candidate = draw == 0 ? scene : draw_scene(config_.seed + 1000 * draw);
    bool all = true;
    for (const std::string& want : config_.bring) {
      all = all && std::any_of(candidate.objects.begin(), candidate.objects.end(),
                               [&](const simulation::PlacedObject& o) {
                                 return want == simulation::category_name(o.model.category);
                               });
    }
    if (all) {
      scene = std::move(candidate);
      break;
    }
  }
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    scene.objects[i].id = static_cast<std::uint32_t>(i);
    report_.scene.emplace_back(simulation::category_name(scene.objects[i].model.category));
  }
  world_.emplace(std::move(scene));
  rng_ = core::Rng(config_.seed ^ 0x5eedULL);
  return {};
}

Result<void, std::string> Session::open_arm() {
  simulation::SimJacoConfig arm;
  arm.start_state = jaco::ArmState::READY_STANDBY;
  sim_.add_arm(std::move(arm));
  sim_.run_for(std::chrono::nanoseconds(START_NS));
  auto devices = jaco::list_arms(sim_);
  if (!devices || devices.value().empty()) return err(std::string("the simulated arm is missing"));
  auto opened = jaco::JacoController::open(sim_, devices.value().front());
  if (!opened) return err("the simulated arm: " + jaco::to_string(opened.error()));
  arm_ = std::move(opened).value();
  next_cycle_ns_ = now();
  return {};
}

void Session::take_objects() noexcept {
  bool got = false;
  while (objects_->poll(list_)) got = true;
  if (!got || perception_dead_) return;
  seen_.clear();
  seen_stamp_ns_ = list_.host_stamp_ns;
  for (std::uint32_t k = 0; k < list_.count; ++k) {
    const engine::ObjectEntry& e = list_.objects[k];
    if ((e.flags & engine::OBJECT_DESCRIBED) == 0U) continue;
    Seen s;
    s.track = static_cast<std::uint32_t>(e.track_id);
    s.label = e.unknown != 0U ? std::string() : std::string(e.label.view());
    std::array<float, 16> f{};
    std::copy(std::begin(e.frame), std::end(e.frame), f.begin());
    s.box = manipulation::upright_box(
        manipulation::object_box_in_base(base_from_camera_, f, {e.bbox[0], e.bbox[1], e.bbox[2]}),
        job_options_.grasp.table);
    s.centre = s.box.base_from_object.translation();
    seen_.push_back(std::move(s));
  }
}

std::size_t Session::fill_obstacles(const Seen* target, const Vector3d& hand, bool holding) {
  std::size_t used = 0;
  for (const Seen& o : seen_) {
    if (!is_target(o, target) && !(holding && (o.centre - hand).norm() < HAND_HIDES_M))
      used = add_spheres(o, used);
  }
  return used;
}

const Seen* Session::find_seen(std::uint32_t track, const Vector3d& near, const std::string& label,
                               double same_label_m, double any_m) const {
  const Seen* best = nullptr;
  double best_d = 0.0;
  for (const Seen& o : seen_) {
    if (o.track == track) return &o;
    const double d = (o.centre - near).norm();
    if ((d < any_m || (d < same_label_m && o.label == label)) && (best == nullptr || d < best_d)) {
      best = &o;
      best_d = d;
    }
  }
  return best;
}

std::size_t Session::add_spheres(const Seen& o, std::size_t used) {
  if (used + manipulation::MAX_BOX_SPHERES > others_.size()) return used;
  return used + manipulation::cover_box(
                    o.box, std::span(others_).subspan(used, manipulation::MAX_BOX_SPHERES));
}

std::string Session::truth_near(const Vector3d& base_point) const {
  const simulation::Scene& scene = world_->scene();
  std::string best;
  double best_d = 0.06;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const Vector3d c = to_base(world_->centre(i));
    const double d = (c - base_point).head<2>().norm();
    if (d < best_d) {
      best_d = d;
      best = simulation::category_name(scene.objects[i].model.category);
    }
  }
  return best;
}

void Session::teach() {
  const simulation::Scene& scene = world_->scene();
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    LearningCommand c;
    c.kind = LearningCommand::Kind::TEACH;
    c.by_position = true;
    const simulation::Vec3 p = world_->centre(i);
    c.position = {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
    (void)c.label.try_assign(simulation::category_name(scene.objects[i].model.category));
    if (teacher_->send(c) != 0) ++teaches_sent_;
  }
}

void Session::plan_task() {
  std::vector<std::string> known;
  for (const learning::CategorySummary& c : learning_->learner().categories())
    known.emplace_back(c.label.view());
  if (config_.task == TableTask::SERVE_A_MEAL) {
    for (const std::string& want : config_.bring) {
      if (std::find(known.begin(), known.end(), want) == known.end()) {
        report_.refused = "nobody taught the category '" + want + "'";
        return;
      }
    }
  }
  std::vector<manipulation::TableObject> objects;
  for (const Seen& s : seen_) {
    objects.push_back({s.track, s.label, s.centre});
    ++report_.perceived;
    if (!s.label.empty() && s.label == truth_near(s.centre)) ++report_.recognised;
  }
  if (config_.task == TableTask::CLEAR_TABLE) {
    manipulation::ClearTableOptions o;
    o.area = config_.area;
    o.table_items = config_.keep;
    plan_ = manipulation::plan_clear_table(objects, o);
  } else {
    manipulation::ServeOptions o;
    o.categories = config_.bring;
    o.user_place = config_.user_place;
    plan_ = manipulation::plan_serve_a_meal(objects, o);
  }
  for (const manipulation::TaskStay& s : plan_.stays) {
    const auto it =
        std::find_if(seen_.begin(), seen_.end(), [&](const Seen& x) { return x.track == s.track; });
    report_.stays.push_back({s.track, s.label,
                             it == seen_.end() ? std::string() : truth_near(it->centre),
                             manipulation::to_string(s.reason)});
  }
  for (const manipulation::TaskMove& m : plan_.moves) {
    const auto it =
        std::find_if(seen_.begin(), seen_.end(), [&](const Seen& x) { return x.track == m.track; });
    MoveReport r;
    r.track = m.track;
    r.label = m.label;
    r.to = m.place;
    r.truth = truth_near(it->centre);
    report_.moves.push_back(std::move(r));
    planned_.push_back(it->centre);
  }
}

bool Session::park() {
  const jaco::ArmSnapshot a = arm_->snapshot();
  if (a.control != jaco::ControlState::IDLE) return parking_;
  parking_ = false;
  if (jaco::max_joint_error(job_options_.initial, a.joints) <= config_.limits.joint_tolerance_deg)
    return false;
  std::size_t used = 0;  // every object is an obstacle here: no target yet
  for (const Seen& o : seen_) used = add_spheres(o, used);
  if (manipulation::joint_path_blocked(a.joints, job_options_.initial,
                                       std::span(others_).first(used),
                                       config_.limits.obstacle_clearance_m))
    return false;
  jaco::ArmCommand c;
  c.kind = jaco::ArmCommand::Kind::MOVE_JOINTS;
  c.joints = job_options_.initial;
  parking_ = arm_->submit(c).has_value();  // refused (a fault): nothing moves
  return parking_;
}

void Session::start_move() {
  MoveReport& r = report_.moves[move_];
  const Seen* s = find_seen(r.track, planned_[move_], {}, 0.0, 0.06);
  // A track's label flickers to Unknown in some frames (the tracker's fragments); another label is
  // another object.
  if (s != nullptr && !s->label.empty() && s->label != r.label) s = nullptr;
  // Seen behind the arm, its centre is not where it is (a cut view).
  const bool cut = s != nullptr && arm_hides(s->centre, 0.5 * s->box.extents.head<2>().norm());
  if (s == nullptr || cut) {
    // The arm, where the last job left it, may hide it from the camera: it goes to the initial pose
    // first. Then the tracker may be re-forming its track: look again for 3 s.
    if (park()) {
      waiting_ = true;
      return;
    }
    if (++unseen_frames_ < 30) {
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
  manipulation::GraspOptions& g = job_options_.grasp;
  g.seed = arm_->snapshot().joints;
  const auto plan = manipulation::plan_grasp(s->box, g);
  if (!plan.has_value()) {
    r.failure = std::string("no grasp: ") + manipulation::to_string(plan.error());
    ++move_;
    return;
  }
  if (plan->best() == nullptr) {
    r.failure = "no feasible grasp";
    if (plan->rejected_count > 0)
      r.failure += std::string(": ") + manipulation::to_string(plan->rejected[0].reason);
    ++move_;
    return;
  }
  target_track_ = s->track;
  target_centre_ = s->centre;
  target_label_ = r.label;
  const Seen* target = current_target();
  const Vector3d tool = jaco::forward_kinematics(job_options_.initial).translation();
  const auto obstacles =
      std::span<const manipulation::Obstacle>(others_).first(fill_obstacles(target, tool, false));
  // Carry high enough that the hand passes 10 cm above the tallest other object (0.15-0.30 m).
  double tallest = 0.0;
  for (const Seen& o : seen_) {
    if (!is_target(o, target))
      tallest =
          std::max(tallest, job_options_.grasp.table.height_of(o.centre) + 0.5 * o.box.extents.z());
  }
  const double wanted =
      std::clamp(tallest + 0.10 - job_options_.grasp.table.height_of(s->centre), 0.15, 0.30);
  // Other lifts when that one's job is blocked or out of reach: higher to pass over, lower to
  // reach.
  std::array<double, 5> lifts{wanted, wanted + 0.05, wanted + 0.10, wanted - 0.05, LOWEST_LIFT_M};
  const auto lifts_end = std::unique(
      lifts.begin(),
      std::remove_if(lifts.begin(), lifts.end(), [](double l) { return l < LOWEST_LIFT_M; }));
  const double clear = config_.limits.obstacle_clearance_m;
  const jaco::JointAngles arm_now = arm_->snapshot().joints;
  std::optional<manipulation::PickPlaceJob> job;
  std::string why;  // why the preferred job (own spot, best grasp, first lift) is not the one
  // The move's own spot first; then the spots of the moves still to come (a spot the arm cannot
  // reach with this object may suit another one: they swap). At each, the jobs of every grasp (best
  // first) and lift, solved once; the first whose every move keeps clear of the other objects
  // along its joint-space path and inside the safety limits, with a margin first (a perceived box
  // shifts by a centimetre or two between frames, and the manager checks every frame), then
  // without.
  std::vector<std::pair<manipulation::PickPlaceJob, const manipulation::Grasp*>> made;
  std::size_t spot = move_;
  for (; spot < report_.moves.size() && !job; ++spot) {
    const Vector3d place(report_.moves[spot].to.x(), report_.moves[spot].to.y(), s->centre.z());
    made.clear();
    for (std::size_t k = 0; k < plan->feasible_count; ++k) {
      for (auto l = lifts.begin(); l != lifts_end; ++l) {
        job_options_.lift_m = *l;
        auto m = manipulation::make_pick_place_job(s->track, s->centre, plan->feasible[k], place,
                                                   job_options_);
        if (m)
          made.emplace_back(*m, &plan->feasible[k]);
        else if (spot == move_ && k == 0 && l == lifts.begin())
          why = "no job: " + m.error();
      }
    }
    for (const double margin : {PLAN_MARGIN_M, 0.0}) {
      for (const auto& [candidate, grasp] : made) {
        auto ok = manipulation::check_job_paths(candidate, arm_now, obstacles, clear + margin,
                                                jaco::SafetyLimits{});
        if (ok) {
          job = candidate;
          r.grasp = manipulation::to_string(grasp->kind);
          break;
        }
        if (why.empty() && margin == 0.0) why = "no clear job: " + ok.error();
      }
      if (job) break;
    }
  }
  if (job && spot - 1 != move_) std::swap(r.to, report_.moves[spot - 1].to);
  target_place_ = r.to;
  if (!job) {
    r.failure = why;
    ++move_;
    return;
  }
  target_object_ = -1;  // the world's object there (to check where it ends up)
  double best = 0.10;
  for (std::size_t i = 0; i < world_->scene().objects.size(); ++i) {
    const double d = (to_base(world_->centre(i)) - s->centre).head<2>().norm();
    if (d < best) {
      best = d;
      target_object_ = static_cast<int>(world_->scene().objects[i].id);
      target_start_ = to_base(world_->centre(i));
    }
  }
  held_ = manipulation::held_object(jaco::forward_kinematics(job->grasp).translation(), s->centre,
                                    s->box.extents, job_options_.grasp.table.normal);
  move_start_ns_ = now();
  (void)manager_.start(*job, now());
  stage_ = Stage::RUNNING;
}

void Session::finish_move() {
  MoveReport& r = report_.moves[move_];
  r.seconds = 1e-9 * static_cast<double>(now() - move_start_ns_);
  std::array<manipulation::Decision, manipulation::ExecutionManager::LOG_SIZE> log{};
  const std::size_t n = manager_.decisions(log);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t end = i + 1 < n ? log[i + 1].stamp_ns : now();
    if (log[i].to != Phase::DONE && log[i].to != Phase::ABORTED)
      r.operators.push_back(
          {manipulation::to_string(log[i].to), 1e-9 * static_cast<double>(end - log[i].stamp_ns)});
    char line[160];
    std::snprintf(line, sizeof line, "%.2f s %s -> %s: %s",
                  1e-9 * static_cast<double>(log[i].stamp_ns - move_start_ns_),
                  manipulation::to_string(log[i].from), manipulation::to_string(log[i].to),
                  log[i].why);
    r.decisions.emplace_back(line);
  }
  r.done = manager_.phase() == Phase::DONE;
  if (!r.done) r.failure = manipulation::to_string(manager_.abort_reason());
  const int index =
      target_object_ >= 0 ? world_->find(static_cast<std::uint32_t>(target_object_)) : -1;
  if (index >= 0 && world_->held() != index) {
    const auto i = static_cast<std::size_t>(index);
    const Vector3d c = to_base(world_->centre(i));
    // Moved as planned: the object's own displacement is the plan's (spot minus the perceived
    // centre) within ARRIVED_M. (Its model origin is not its perceived centre: a mug's box holds
    // its handle.)
    const Vector2d planned = r.to - target_centre_.head<2>();
    r.error_m = ((c - target_start_).head<2>() - planned).norm();
    r.arrived = world_->scene().objects[i].base_m == 0.0 && r.error_m < ARRIVED_M;
  }
  const manipulation::AbortReason why = manager_.abort_reason();
  ++move_;
  if (why == manipulation::AbortReason::ARM_FAULT || why == manipulation::AbortReason::ARM_ESTOP ||
      why == manipulation::AbortReason::REFUSED || (!r.done && was_holding_)) {
    report_.stopped = std::string("move ") + std::to_string(move_) + " ended with " +
                      manipulation::to_string(why) +
                      (was_holding_ ? " while holding the object" : "") + ": the task stops";
    for (std::size_t k = move_; k < report_.moves.size(); ++k)
      report_.moves[k].failure = "not started: the task stopped";
    stage_ = Stage::FINISH;
    stage_frame_ = frame_;
    return;
  }
  stage_ = Stage::MOVE;
}

void Session::fire_event() {
  if (event_fired_ || config_.event == TaskEvent::NONE || move_ != 0 ||
      manager_.phase() != config_.event_phase)
    return;
  event_fired_ = true;
  switch (config_.event) {
    case TaskEvent::MOVE_TARGET: {
      const int index = world_->find(static_cast<std::uint32_t>(std::max(target_object_, 0)));
      if (index >= 0) {
        const simulation::PlacedObject& o =
            world_->scene().objects[static_cast<std::size_t>(index)];
        (void)world_->move_object(static_cast<std::size_t>(index), o.table_x + 0.10, o.table_y);
      }
      break;
    }
    case TaskEvent::STOP_PERCEPTION:
      perception_dead_ = true;
      break;
    case TaskEvent::UNPLUG_ARM:
      sim_.unplug(0);
      break;
    default:
      break;
  }
}

void Session::arm_cycle() noexcept {
  const jaco::ArmSnapshot s = arm_->snapshot();
  const Vector3d tool_base = jaco::forward_kinematics(s.joints).translation();
  const Vector3d tool = camera_from_base_ * tool_base;
  world_->update({tool.x(), tool.y(), tool.z()},
                 manipulation::opening_for_finger(s.fingers[0], job_options_));
  if (stage_ == Stage::RUNNING && world_->held() >= 0 &&
      static_cast<int>(world_->scene().objects[static_cast<std::size_t>(world_->held())].id) ==
          target_object_)
    report_.moves[move_].held = true;
  engine::ArmStatePayload p;
  p.reset();
  p.flags = (s.estop ? engine::ARM_ESTOP : 0U) | (s.fault ? engine::ARM_FAULT : 0U);
  p.arm_state = static_cast<std::int32_t>(s.arm_state);
  p.cycle = s.cycle;
  p.stamp_ns = now();
  p.control = static_cast<std::uint32_t>(s.control);
  for (std::size_t j = 0; j < jaco::JOINTS; ++j) p.joints_deg[j] = s.joints[j];
  for (std::size_t f = 0; f < jaco::FINGERS; ++f) p.fingers[f] = s.fingers[f];
  if (stage_ == Stage::RUNNING && manager_.holding()) {  // the body filter removes it with the arm
    for (int k = 0; k < 3; ++k) {
      p.held_m[k] = held_.a[k];
      p.held_m[3 + k] = held_.b[k];
    }
    p.held_m[6] = held_.radius_m;
  }
  arm_states_.write(p);
  if (stage_ == Stage::RUNNING && manager_.running()) {
    fire_event();
    manipulation::PerceptionInput in;
    in.stamp_ns = seen_stamp_ns_;
    const bool holding = world_->held() >= 0;
    // The hand's own filter cuts a target it is about to take, and the arm between the camera and
    // the target cuts its view: such a view is not evidence of where it is.
    const double radius = held_.radius_m;  // the target's footprint
    const Seen* t = current_target();
    const bool cut = t != nullptr && arm_hides(t->centre, radius);
    if (t != nullptr && (t->centre - tool_base).norm() > HAND_HIDES_M && !cut) {
      in.target_seen = true;
      in.target_centre = t->centre;
    }
    in.target_hidden =
        !in.target_seen && (cut || (target_centre_ - tool_base).norm() < HAND_HIDES_M ||
                            arm_hides(target_centre_, radius));
    in.others = std::span(others_).first(fill_obstacles(t, tool_base, holding));
    manipulation::ArmInput a;
    a.joints = s.joints;
    a.fingers = {s.fingers[0], s.fingers[1], s.fingers[2]};
    a.idle = s.control == jaco::ControlState::IDLE;
    a.fault = s.fault;
    a.estop = s.estop;
    was_holding_ = manager_.holding();
    const manipulation::ArmRequest r = manager_.step(now(), a, in);
    if (r.kind != manipulation::ArmRequest::Kind::NONE) {
      jaco::ArmCommand c;
      c.speed_fraction = r.speed_fraction;
      if (r.kind == manipulation::ArmRequest::Kind::MOVE_JOINTS) {
        c.kind = jaco::ArmCommand::Kind::MOVE_JOINTS;
        c.joints = r.joints;
      } else if (r.kind == manipulation::ArmRequest::Kind::MOVE_FINGERS) {
        c.kind = jaco::ArmCommand::Kind::MOVE_FINGERS;
        c.fingers = {r.fingers, r.fingers, r.fingers};
      } else {
        c.kind = jaco::ArmCommand::Kind::STOP;
      }
      if (!arm_->submit(c)) manager_.refused(now());
    }
  }
  if (manager_.running() || parking_) arm_->keep_alive();
  arm_->cycle();
  next_cycle_ns_ += jaco::ARM_PERIOD_NS;
  if (now() < next_cycle_ns_) sim_.run_for(std::chrono::nanoseconds(next_cycle_ns_ - now()));
  next_cycle_ns_ = std::max(next_cycle_ns_, now());
}

void Session::advance_stage() {
  switch (stage_) {
    case Stage::SETTLE:
      if (frame_ >= config_.settle_frames) {
        teach();
        stage_ = Stage::TEACH;
        stage_frame_ = frame_;
      }
      break;
    case Stage::TEACH: {
      LearningAck ack;
      while (teacher_->poll(ack)) {
        ++acks_;
        if (ack.outcome == LearningAck::Outcome::LEARNED ||
            ack.outcome == LearningAck::Outcome::STORED)
          ++report_.taught;
      }
      if (acks_ >= teaches_sent_ || frame_ - stage_frame_ > 30) {
        stage_ = Stage::RECOGNISE;
        stage_frame_ = frame_;
      }
      break;
    }
    case Stage::RECOGNISE:
      if (frame_ - stage_frame_ >= config_.recognise_frames) {
        plan_task();
        stage_ = report_.refused.empty() ? Stage::MOVE : Stage::END;
      }
      break;
    case Stage::MOVE:
      waiting_ = false;
      while (stage_ == Stage::MOVE && move_ < report_.moves.size() && !waiting_) start_move();
      if (stage_ == Stage::MOVE && !waiting_) {
        stage_ = Stage::FINISH;
        stage_frame_ = frame_;
      }
      break;
    case Stage::RUNNING:  // next_frame finishes the move as soon as the manager ends
      break;
    case Stage::FINISH:
      if (frame_ - stage_frame_ >= 5) stage_ = Stage::END;
      break;
    case Stage::END:
      break;
  }
}

const simulation::Scene* Session::next_frame(kernels::PointCloud& cloud) noexcept {
  take_objects();
  if (config_.on_frame && frame_ > 0) {
    TaskFrameView view;
    view.frame = frame_ - 1;
    view.seconds = 1e-9 * static_cast<double>(now() - START_NS);
    view.scene = &world_->scene();
    view.base_from_camera = &base_from_camera_;
    const int held = world_->held();
    view.held_object_id =
        held >= 0 ? static_cast<int>(world_->scene().objects[static_cast<std::size_t>(held)].id)
                  : -1;
    view.phase = manipulation::to_string(manager_.phase());
    config_.on_frame(view);
  }
  advance_stage();
  if (stage_ == Stage::END) return nullptr;
  if (1e-9 * static_cast<double>(now() - START_NS) > config_.max_seconds) {
    report_.stopped = "the simulated time limit was reached";
    if (manager_.running()) manager_.request_stop(now());
    stage_ = Stage::END;
    return nullptr;
  }
  const std::int64_t end = now() + config_.frame_period_ns;
  while (now() < end) arm_cycle();
  if (stage_ == Stage::RUNNING && !manager_.running()) finish_move();
  // The arm as the camera sees it: the link model without the filter's margin.
  manipulation::ArmBodyModel body;
  body.margin_m = 0.0;
  const std::size_t n = manipulation::arm_body_capsules(arm_->snapshot().joints, base_from_camera_,
                                                        body, jaco::jaco2_geometry(), capsules_);
  sight_count_ = n;  // the same arm as the body filter cuts it: with its margin
  for (std::size_t i = 0; i < n; ++i) {
    sight_[i] = capsules_[i];
    sight_[i].radius += static_cast<float>(manipulation::ArmBodyModel{}.margin_m);
  }
  std::vector<simulation::BodyCapsule>& robot = world_->robot();
  robot.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const kernels::Capsule& c = capsules_[i];
    robot[i] = {{c.a[0], c.a[1], c.a[2]}, {c.b[0], c.b[1], c.b[2]}, c.radius};
  }
  simulation::render_scene(world_->scene(), render_, rng_, cloud);
  cloud.info.frame_id = frame_;
  cloud.info.sensor_stamp_ns = now();
  cloud.info.host_stamp_ns = now();
  ++frame_;
  return &world_->scene();
}

Result<TableTaskReport, std::string> Session::run() {
  if (auto ok = build_world(); !ok) return err(ok.error());
  if (auto ok = open_arm(); !ok) return err(ok.error());
  camera_from_base_ = base_from_camera_.inverse();
  world_->robot().reserve(simulation::MAX_SCENE_CAPSULES);
  job_options_.lift_m = 0.20;
  report_.task = to_string(config_.task);
  report_.seed = config_.seed;
  manager_ = manipulation::ExecutionManager(config_.limits);
  auto learning = LearningService::open(LearningSettings{});
  if (!learning) return err(learning.error());
  learning_ = std::move(*learning);
  teacher_ = learning_->connect();
  objects_ = hub_.subscribe(8);
  SessionLog log;
  engine::NodeRegistry registry =
      make_tabletop_registry(*learning_, log, &hub_, nullptr, &arm_states_);
  add_world_source_node(registry, this);
  auto spec = engine::parse_graph(std::string(embedded_tabletop_yaml()), "embedded tabletop");
  if (!spec) return err(engine::to_string(spec.error()));
  for (engine::NodeSpec& node : spec->nodes) {
    if (node.name == "source") {
      node.kind = "world_source";
      node.params = {};
    }
    if (node.kind == "recognise") node.params.assign("instructor", "0");  // the person teaches
  }
  spec->period_ns = 0;      // simulated time: as fast as the graph goes
  spec->max_in_flight = 1;  // lock step: each frame's objects arrive before the next frame
  const Eigen::Quaterniond q(base_from_camera_.linear());
  const Vector3d t = base_from_camera_.translation();
  char frames[256];
  std::snprintf(frames, sizeof frames, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", t.x(), t.y(),
                t.z(), q.w(), q.x(), q.y(), q.z());
  engine::ParamMap body;
  body.assign("base_from_camera", frames);
  body.assign("state", "channel");
  if (auto ok = insert_body_filter(*spec, body); !ok) return err(ok.error());
  auto graph = engine::build_graph(*spec, registry);
  if (!graph) return err(engine::to_string(graph.error()));
  engine::Engine engine(**graph, engine::EngineConfig{1});
  engine.run({});
  report_.frames = frame_;
  report_.seconds = 1e-9 * static_cast<double>(now() - START_NS);
  report_.fallen = world_->fallen();
  if (const engine::Node* filter = engine.node("body"); filter != nullptr) {
    std::array<engine::DeviceCounter, engine::MAX_DEVICE_COUNTERS> c{};
    const std::size_t k = filter->device_counters(c);
    for (std::size_t i = 0; i < k; ++i) {
      if (std::string_view(c[i].name).starts_with("dropped_")) report_.body_dropped += c[i].value;
    }
  }
  return std::move(report_);
}

}  // namespace

Result<TableTaskReport, std::string> run_table_task(const TableTaskConfig& config) {
  Session session(config);
  return session.run();
}

}  // namespace orthoflow::graphs
