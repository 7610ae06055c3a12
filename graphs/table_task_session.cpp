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
#include "graphs/live_table_task.hpp"
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

std::size_t TableTaskReport::first_moves() const noexcept {
  return static_cast<std::size_t>(std::count_if(
      moves.begin(), moves.end(), [](const MoveReport& m) { return m.attempt == 1; }));
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

simulation::Scene draw_task_table(const TableTaskConfig& config, std::uint64_t seed) {
  simulation::SceneConfig scene_config;
  scene_config.objects = std::min<std::uint32_t>(config.objects + 6, simulation::MAX_SCENE_OBJECTS);
  scene_config.categories =
      config.categories.empty()
          ? std::vector<simulation::Category>{simulation::Category::BOTTLE,
                                              simulation::Category::MUG, simulation::Category::CAN,
                                              simulation::Category::FLASK,
                                              simulation::Category::PLATE}
          : config.categories;
  simulation::Scene scene = simulation::make_scene(scene_config, seed);
  scene.table = simulation::TableSpec{};  // the table the robot frames assume
  const Isometry3d base_from_camera = synthetic_base_from_camera(scene.table);
  const simulation::TableFrame frame = simulation::table_frame(scene.table);
  // Keep the objects that stand on this table, clear of the arm's base column, up to the count.
  std::vector<simulation::PlacedObject> kept;
  for (const simulation::PlacedObject& o : scene.objects) {
    const double r = o.model.footprint_radius;
    const bool on_table = std::fabs(o.table_x) + r < 0.5 * scene.table.width_m - 0.02 &&
                          std::fabs(o.table_y) + r < 0.5 * scene.table.depth_m - 0.02;
    const simulation::Vec3 p = frame.point(o.table_x, o.table_y);
    const Vector2d at = (base_from_camera * Vector3d(p[0], p[1], p[2])).head<2>();
    // The placing area and the user's place start empty (a tray, a place setting).
    const Vector2d margin(r + 0.02, r + 0.02);
    const manipulation::TableArea area{config.area.min - margin, config.area.max + margin};
    bool free = true;
    if (config.task == TableTask::CLEAR_TABLE) {
      free = !area.contains(at);
    } else {
      for (std::size_t k = 0; k < std::max<std::size_t>(config.bring.size(), 1); ++k)
        free = free && (at - config.user_place - Vector2d(0.15 * double(k), 0.0)).norm() > r + 0.08;
    }
    if (on_table && free && at.norm() > 0.30 && kept.size() < config.objects) kept.push_back(o);
  }
  scene.objects = std::move(kept);
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    scene.objects[i].id = static_cast<std::uint32_t>(i);
  return scene;
}

namespace {

constexpr std::int64_t START_NS = 1'000'000'000;  // frame stamps must not be 0
constexpr double ARRIVED_M = 0.05;

class Session final : public WorldFeed {
 public:
  explicit Session(const TableTaskConfig& config) : config_(config) {}

  Result<TableTaskReport, std::string> run();
  const simulation::Scene* next_frame(kernels::PointCloud& cloud) noexcept override;

 private:
  enum class Stage { SETTLE, TEACH, RECOGNISE, TASK, FINISH, END };

  Result<void, std::string> build_world();
  /// The seeded table: make_scene's objects on the robot frames' table, clear of the arm's base
  /// column and of the placing area / the user's place, up to config_.objects.
  [[nodiscard]] simulation::Scene draw_scene(std::uint64_t seed);
  Result<void, std::string> open_arm();
  void make_runner();
  void take_objects() noexcept;
  void advance_stage();
  void teach();
  void plan_task();
  /// The world's object under the move's target (ground truth, to check where it ends up).
  void move_started(std::size_t move, const manipulation::SeenObject& s);
  void move_ended(std::size_t move);
  void arm_cycle() noexcept;
  void fire_event();
  void copy_records();
  void grow_reports();
  [[nodiscard]] std::string truth_near(const Vector3d& base_point) const;
  [[nodiscard]] std::int64_t now() const noexcept { return sim_.clock().now_ns(); }
  [[nodiscard]] Vector3d to_base(const simulation::Vec3& p) const {
    return base_from_camera_ * Vector3d(p[0], p[1], p[2]);
  }
  [[nodiscard]] bool submit(const jaco::ArmCommand& c) { return arm_->submit(c).has_value(); }

  TableTaskConfig config_;
  TableTaskReport report_;
  Isometry3d base_from_camera_ = Isometry3d::Identity();
  Isometry3d camera_from_base_ = Isometry3d::Identity();
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
  std::vector<manipulation::SeenObject> seen_;
  core::Rng rng_{0};
  simulation::RenderOptions render_{};
  manipulation::JobOptions job_options_{};
  std::optional<manipulation::TableTaskRunner> runner_;
  manipulation::TableTaskRunner::Submit submit_;
  Stage stage_ = Stage::SETTLE;
  std::uint64_t frame_ = 0;
  std::uint64_t stage_frame_ = 0;
  std::size_t teaches_sent_ = 0, acks_ = 0;
  int target_object_ = -1;                    // world object id of the current move's target
  Vector3d target_start_ = Vector3d::Zero();  // the world's object centre at the move's start
  bool event_fired_ = false, perception_dead_ = false;
  std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES> capsules_{};
};

simulation::Scene Session::draw_scene(std::uint64_t seed) {
  simulation::Scene scene = draw_task_table(config_, seed);
  base_from_camera_ = synthetic_base_from_camera(scene.table);
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

void Session::make_runner() {
  manipulation::TableTaskOptions o;
  o.task = config_.task;
  o.keep = config_.keep;
  o.bring = config_.bring;
  o.area = config_.area;
  o.user_place = config_.user_place;
  o.limits = config_.limits;
  o.job = job_options_;
  o.base_from_camera = base_from_camera_;
  runner_.emplace(std::move(o));
  runner_->on_move_started = [this](std::size_t m, const manipulation::SeenObject& s) {
    move_started(m, s);
  };
  runner_->on_move_ended = [this](std::size_t m) { move_ended(m); };
  submit_ = [this](const jaco::ArmCommand& c) { return submit(c); };
}

void Session::take_objects() noexcept {
  bool got = false;
  while (objects_->poll(list_)) got = true;
  if (!got || perception_dead_) return;
  seen_objects(list_, base_from_camera_, job_options_.grasp.table, seen_);
  runner_->on_objects(seen_, list_.host_stamp_ns);
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
  if (auto ok = runner_->start(known); !ok) {
    report_.refused = ok.error();
    return;
  }
  for (const manipulation::SeenObject& s : runner_->seen()) {
    ++report_.perceived;
    if (!s.label.empty() && s.label == truth_near(s.centre)) ++report_.recognised;
  }
  for (const manipulation::StayRecord& s : runner_->stays()) {
    const auto it =
        std::find_if(runner_->seen().begin(), runner_->seen().end(),
                     [&](const manipulation::SeenObject& x) { return x.track == s.track; });
    report_.stays.push_back({s.track, s.label,
                             it == runner_->seen().end() ? std::string() : truth_near(it->centre),
                             s.reason});
  }
  for (std::size_t m = 0; m < runner_->moves().size(); ++m) {
    MoveReport r;
    r.truth = truth_near(runner_->planned()[m]);
    report_.moves.push_back(std::move(r));
  }
  copy_records();
}

void Session::grow_reports() {
  // The runner's retries (a failed move tried once more at the end) get a report each.
  while (report_.moves.size() < runner_->moves().size()) {
    MoveReport r;
    r.truth = report_.moves[runner_->moves()[report_.moves.size()].retry_of].truth;
    report_.moves.push_back(std::move(r));
  }
}

void Session::copy_records() {
  grow_reports();
  for (std::size_t m = 0; m < report_.moves.size(); ++m)
    static_cast<manipulation::MoveRecord&>(report_.moves[m]) = runner_->moves()[m];
}

void Session::move_started(std::size_t /*move*/, const manipulation::SeenObject& s) {
  grow_reports();
  target_object_ = -1;
  double best = 0.10;
  for (std::size_t i = 0; i < world_->scene().objects.size(); ++i) {
    const double d = (to_base(world_->centre(i)) - s.centre).head<2>().norm();
    if (d < best) {
      best = d;
      target_object_ = static_cast<int>(world_->scene().objects[i].id);
      target_start_ = to_base(world_->centre(i));
    }
  }
}

void Session::move_ended(std::size_t move) {
  MoveReport& r = report_.moves[move];
  const manipulation::MoveRecord& record = runner_->moves()[move];
  const int index =
      target_object_ >= 0 ? world_->find(static_cast<std::uint32_t>(target_object_)) : -1;
  if (index >= 0 && world_->held() != index) {
    const auto i = static_cast<std::size_t>(index);
    const Vector3d c = to_base(world_->centre(i));
    // Moved as planned: the object's own displacement is the plan's (spot minus the perceived
    // centre) within ARRIVED_M. (Its model origin is not its perceived centre: a mug's box holds
    // its handle.)
    const Vector2d planned = record.to - runner_->target_centre().head<2>();
    r.error_m = ((c - target_start_).head<2>() - planned).norm();
    r.arrived = world_->scene().objects[i].base_m == 0.0 && r.error_m < ARRIVED_M;
  }
}

void Session::fire_event() {
  const manipulation::ExecutionManager& manager = runner_->manager();
  if (event_fired_ || config_.event == TaskEvent::NONE || runner_->move_index() != 0 ||
      runner_->state() != manipulation::TableTaskRunner::State::RUNNING || !manager.running() ||
      manager.phase() != config_.event_phase)
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
  const Vector3d tool = camera_from_base_ * jaco::forward_kinematics(s.joints).translation();
  world_->update({tool.x(), tool.y(), tool.z()},
                 manipulation::opening_for_finger(s.fingers[0], job_options_));
  const bool running = runner_->state() == manipulation::TableTaskRunner::State::RUNNING;
  if (running && world_->held() >= 0 &&
      static_cast<int>(world_->scene().objects[static_cast<std::size_t>(world_->held())].id) ==
          target_object_)
    report_.moves[runner_->move_index()].held = true;
  manipulation::HeldObject held;
  (void)runner_->held(held);  // the body filter removes it with the arm
  arm_states_.write(arm_state_payload(s, now(), held));
  fire_event();
  if (runner_->cycle(now(), s, submit_)) arm_->keep_alive();
  arm_->cycle();
  next_cycle_ns_ += jaco::ARM_PERIOD_NS;
  if (now() < next_cycle_ns_) sim_.run_for(std::chrono::nanoseconds(next_cycle_ns_ - now()));
  next_cycle_ns_ = std::max(next_cycle_ns_, now());
}

void Session::advance_stage() {
  using State = manipulation::TableTaskRunner::State;
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
        stage_ = report_.refused.empty() ? Stage::TASK : Stage::END;
      }
      break;
    case Stage::TASK:
      runner_->step(now(), arm_->snapshot(), submit_);
      if (runner_->state() == State::FINISHED) {
        stage_ = Stage::FINISH;
        stage_frame_ = frame_;
      }
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
    view.phase = manipulation::to_string(runner_->manager().phase());
    config_.on_frame(view);
  }
  advance_stage();
  if (stage_ == Stage::END) return nullptr;
  if (1e-9 * static_cast<double>(now() - START_NS) > config_.max_seconds) {
    report_.stopped = "the simulated time limit was reached";
    runner_->halt(now());
    stage_ = Stage::END;
    return nullptr;
  }
  const std::int64_t end = now() + config_.frame_period_ns;
  while (now() < end) arm_cycle();
  if (stage_ == Stage::TASK) {
    runner_->finish_step(now());
    if (runner_->state() == manipulation::TableTaskRunner::State::FINISHED) {
      report_.stopped = runner_->stopped();
      stage_ = Stage::FINISH;
      stage_frame_ = frame_;
    }
  }
  // The arm as the camera sees it: the link model without the filter's margin.
  const jaco::JointAngles joints = arm_->snapshot().joints;
  manipulation::ArmBodyModel body;
  body.margin_m = 0.0;
  const std::size_t n = manipulation::arm_body_capsules(joints, base_from_camera_, body,
                                                        jaco::jaco2_geometry(), capsules_);
  runner_->on_arm_body(std::span(capsules_).first(n));  // the runner adds the filter's margin
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
  report_.task = manipulation::to_string(config_.task);
  report_.seed = config_.seed;
  make_runner();
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
  if (runner_->state() != manipulation::TableTaskRunner::State::IDLE) copy_records();
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
