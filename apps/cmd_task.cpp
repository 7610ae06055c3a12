// `orthoflow task plan clear_table|serve_a_meal --robot-frames FRAMES.yaml --objects RUN.jsonl
// ...`: the thesis's table tasks (chapter 8) planned on one frame of `orthoflow run --json-out`,
// from the labels the learner gave (manipulation/table_tasks.hpp): which objects move, in which
// order, to which spot, with each move's grasp and pick-and-place job (or why it cannot be done),
// and why every other object stays. It plans; it moves nothing (docs/MANIPULATION.md section 5).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "apps/option_checks.hpp"
#include "apps/perceived_scene.hpp"
#include "manipulation/pick_place_job.hpp"
#include "manipulation/table_tasks.hpp"

namespace orthoflow::apps {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

struct TaskArgs {
  std::string task;
  std::string frames;
  std::string objects;
  std::optional<std::uint64_t> frame;
  std::vector<double> area;        // clear_table's placing area
  std::vector<std::string> keep;   // clear_table's table items
  std::vector<std::string> bring;  // serve_a_meal's categories
  std::vector<double> user_place;
  bool json = false;
};

void run_task(const TaskArgs& a) {
  const PerceivedScene scene = load_perceived_scene("task", a.frames, a.objects, a.frame);
  manipulation::GraspOptions grasp_options;
  grasp_options.table = scene.table;
  std::vector<manipulation::TableObject> objects;
  std::vector<manipulation::ObjectBox> boxes;
  for (const manipulation::PerceivedObject& o : scene.frame.objects) {
    if (!o.described) continue;  // no frame, no box: nothing to plan with
    boxes.push_back(manipulation::object_box_in_base(scene.base_from_camera, o.frame, o.bbox));
    objects.push_back({static_cast<std::uint32_t>(o.track), o.label,
                       boxes.back().base_from_object.translation(),
                       manipulation::footprint_radius(
                           manipulation::upright_box(boxes.back(), scene.table).extents)});
  }
  manipulation::TaskPlan plan;
  if (a.task == "clear_table") {
    manipulation::ClearTableOptions options;
    options.area = {Vector2d(std::min(a.area[0], a.area[2]), std::min(a.area[1], a.area[3])),
                    Vector2d(std::max(a.area[0], a.area[2]), std::max(a.area[1], a.area[3]))};
    options.table_items = a.keep;
    plan = manipulation::plan_clear_table(objects, options);
  } else {
    manipulation::ServeOptions options;
    options.categories = a.bring;
    options.user_place = Vector2d(a.user_place[0], a.user_place[1]);
    plan = manipulation::plan_serve_a_meal(objects, options);
  }
  nlohmann::json out = {{"task", a.task},
                        {"frame", scene.frame.frame},
                        {"moves", nlohmann::json::array()},
                        {"stays", nlohmann::json::array()}};
  std::size_t ready = 0;
  for (const manipulation::TaskMove& m : plan.moves) {
    std::size_t i = 0;
    while (objects[i].track != m.track) ++i;
    const Vector3d centre = objects[i].centre;
    nlohmann::json entry = {{"track", m.track},
                            {"label", m.label},
                            {"from_m", {centre.x(), centre.y(), centre.z()}},
                            {"to_m", {m.place.x(), m.place.y(), centre.z()}}};
    const auto grasp = manipulation::plan_grasp(boxes[i], grasp_options);
    if (!grasp.has_value()) {
      entry["blocked"] = manipulation::to_string(grasp.error());
    } else if (grasp->best() == nullptr) {
      entry["blocked"] = "no feasible grasp";
    } else {
      manipulation::JobOptions job_options;
      job_options.grasp = grasp_options;
      const auto job = manipulation::make_pick_place_job(
          m.track, centre, *grasp->best(), Vector3d(m.place.x(), m.place.y(), centre.z()),
          job_options);
      entry["grasp"] = manipulation::to_string(grasp->best()->kind);
      if (job.has_value()) {
        entry["job"] = "solved";
        ++ready;
      } else {
        entry["blocked"] = job.error();
      }
    }
    out["moves"].push_back(entry);
  }
  for (const manipulation::TaskStay& s : plan.stays) {
    out["stays"].push_back({{"track", s.track},
                            {"label", s.label.empty() ? nlohmann::json() : nlohmann::json(s.label)},
                            {"reason", manipulation::to_string(s.reason)}});
  }
  out["ready"] = ready;
  if (a.json) {
    std::cout << out.dump() << '\n';
    return;
  }
  std::printf("%s on frame %llu: %zu move(s), %zu ready to run, %zu object(s) stay\n",
              a.task.c_str(), static_cast<unsigned long long>(scene.frame.frame), plan.moves.size(),
              ready, plan.stays.size());
  int n = 0;
  for (const auto& e : out["moves"]) {
    std::printf("%d. track %u (%s) to [%.3f, %.3f]: %s\n", ++n, e["track"].get<unsigned>(),
                e["label"].get<std::string>().c_str(), e["to_m"][0].get<double>(),
                e["to_m"][1].get<double>(),
                e.contains("blocked")
                    ? ("blocked: " + e["blocked"].get<std::string>()).c_str()
                    : (e["grasp"].get<std::string>() + " grasp, job solved").c_str());
  }
  for (const auto& e : out["stays"]) {
    std::printf("stays: track %u (%s): %s\n", e["track"].get<unsigned>(),
                e["label"].is_string() ? e["label"].get<std::string>().c_str() : "Unknown",
                e["reason"].get<std::string>().c_str());
  }
}

}  // namespace

void add_task_command(CLI::App& app) {
  auto a = std::make_shared<TaskArgs>();
  auto* task = app.add_subcommand(
      "task",
      "the table tasks: plan one on a run's objects, or run them on the arm and start / stop them");
  task->require_subcommand(1);
  add_live_task_commands(task);
  auto* cmd = task->add_subcommand(
      "plan",
      "plan clear_table or serve_a_meal on a run's objects (which move, where, in which "
      "order, with their grasps and jobs; it moves nothing)");
  cmd->add_option("task", a->task, "clear_table or serve_a_meal")
      ->required()
      ->check(CLI::IsMember({"clear_table", "serve_a_meal"}));
  cmd->add_option("--robot-frames", a->frames, "robot frames file (base_from_camera)")->required();
  cmd->add_option("--objects", a->objects, "JSON lines of orthoflow run --json-out")->required();
  cmd->add_option("--frame", a->frame, "frame id (default: the last frame with objects)");
  cmd->add_option("--area", a->area,
                  "clear_table: the placing area X0,Y0,X1,Y1 on the table, base frame (m)")
      ->type_name("X0,Y0,X1,Y1")
      ->expected(4)
      ->delimiter(',')
      ->check(table_coordinate());
  cmd->add_option("--keep", a->keep, "clear_table: categories that are table items and stay")
      ->delimiter(',');
  cmd->add_option("--bring", a->bring, "serve_a_meal: the categories to bring, in order")
      ->transform(composed_label())
      ->delimiter(',');
  cmd->add_option("--user-place", a->user_place,
                  "serve_a_meal: the user's place X,Y on the table, base frame (m)")
      ->type_name("X,Y")
      ->expected(2)
      ->delimiter(',')
      ->check(table_coordinate());
  cmd->add_flag("--json", a->json, "one JSON object on stdout");
  cmd->callback([a] {
    const char* missing = a->task == "clear_table" && a->area.empty() ? "clear_table needs --area"
                          : a->task == "serve_a_meal" && a->bring.empty()
                              ? "serve_a_meal needs --bring CATEGORY[,...]"
                          : a->task == "serve_a_meal" && a->user_place.empty()
                              ? "serve_a_meal needs --user-place X,Y"
                              : nullptr;
    if (missing != nullptr) {
      std::cerr << "orthoflow task: " << missing << '\n';
      throw CLI::RuntimeError(EXIT_USAGE);
    }
    run_task(*a);
  });
}

}  // namespace orthoflow::apps
