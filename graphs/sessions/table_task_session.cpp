// run_table_task (graphs/sessions/table_task_session.hpp): the seeded world, the simulated arm
// behind its driver, the learner and the tabletop graph with its world source and body filter,
// built and run to the end. The frames are in table_task_frames.cpp, the report in
// table_task_report.cpp, the seeded table in table_task_scene.cpp (task_session.hpp).
#include "graphs/sessions/table_task_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>

#include "engine/engine.hpp"
#include "graphs/embedded_graphs.hpp"
#include "graphs/nodes/body_filter_node.hpp"
#include "graphs/services/session_log.hpp"
#include "graphs/sessions/task_session.hpp"
#include "graphs/tabletop.hpp"

namespace orthoflow::graphs {

simulation::Scene TaskLoop::draw_scene(std::uint64_t seed) {
  simulation::Scene scene = draw_task_table(config_, seed);
  base_from_camera_ = synthetic_base_from_camera(scene.table);
  return scene;
}

Result<void, std::string> TaskLoop::build_world() {
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

Result<void, std::string> TaskLoop::open_arm() {
  simulation::SimJacoConfig arm;
  arm.start_state = jaco::ArmState::READY_STANDBY;
  sim_.add_arm(std::move(arm));
  sim_.run_for(std::chrono::nanoseconds(TASK_LOOP_START_NS));
  auto devices = jaco::list_arms(sim_);
  if (!devices || devices.value().empty()) return err(std::string("the simulated arm is missing"));
  auto opened = jaco::JacoController::open(sim_, devices.value().front());
  if (!opened) return err("the simulated arm: " + jaco::to_string(opened.error()));
  arm_ = std::move(opened).value();
  next_cycle_ns_ = now();
  return {};
}

void TaskLoop::make_runner() {
  manipulation::TableTaskOptions o;
  o.task = config_.task;
  o.keep = config_.keep;
  o.bring = config_.bring;
  o.area = config_.area;
  o.user_place = config_.user_place;
  o.limits = config_.limits;
  o.job = job_options_;
  o.base_from_camera = robot_base_from_camera_;
  runner_.emplace(std::move(o));
  runner_->on_move_started = [this](std::size_t m, const manipulation::SeenObject& s) {
    move_started(m, s);
  };
  runner_->on_move_ended = [this](std::size_t m) { move_ended(m); };
  submit_ = [this](const jaco::ArmCommand& c) { return submit(c); };
}

Result<TableTaskReport, std::string> TaskLoop::run() {
  if (auto ok = build_world(); !ok) return err(ok.error());
  if (auto ok = open_arm(); !ok) return err(ok.error());
  camera_from_base_ = base_from_camera_.inverse();
  robot_base_from_camera_ = config_.robot_base_from_camera.value_or(base_from_camera_);
  if (config_.robot_base_from_camera) {
    report_.calibrated = true;
    report_.hand_eye_error_mm =
        1e3 * (robot_base_from_camera_.translation() - base_from_camera_.translation()).norm();
    const Eigen::AngleAxisd off(robot_base_from_camera_.linear().transpose() *
                                base_from_camera_.linear());
    report_.hand_eye_error_deg = off.angle() * 180.0 / std::numbers::pi;
  }
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
  const Eigen::Quaterniond q(robot_base_from_camera_.linear());
  const Vector3d t = robot_base_from_camera_.translation();
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
  report_.seconds = 1e-9 * static_cast<double>(now() - TASK_LOOP_START_NS);
  report_.fallen = world_->fallen();
  report_.spills = world_->spills();
  report_.drops = world_->drops();
  if (const engine::Node* filter = engine.node("body"); filter != nullptr) {
    std::array<engine::DeviceCounter, engine::MAX_DEVICE_COUNTERS> c{};
    const std::size_t k = filter->device_counters(c);
    for (std::size_t i = 0; i < k; ++i) {
      if (std::string_view(c[i].name).starts_with("dropped_")) report_.body_dropped += c[i].value;
    }
  }
  return std::move(report_);
}

Result<TableTaskReport, std::string> run_table_task(const TableTaskConfig& config) {
  TaskLoop session(config);
  return session.run();
}

}  // namespace orthoflow::graphs
