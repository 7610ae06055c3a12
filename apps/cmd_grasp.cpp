// `orthoflow grasp --robot-frames FRAMES.yaml --objects RUN.jsonl [--frame N] [--model jaco2|v1]
// [--json]`: the grasp plan of every object of one frame of `orthoflow run --json-out`, in the
// arm's base frame (manipulation/grasp_planner.hpp): the objects' GOOD frames and boxes and the
// table plane, carried through the configured camera pose. Per object: the chosen grasp (kind,
// pre-grasp and grasp positions, approach, finger opening, joint solutions) or why there is none,
// and every rejected candidate with its reason. The frame is the last one with objects unless
// --frame names one. With --place X,Y, each grasped object's pick-and-place job too
// (manipulation/pick_place_job.hpp): the joints of the lift, the carry, the place and the retreat,
// or the step the arm does not reach.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "apps/perceived_scene.hpp"
#include "manipulation/grasp_planner.hpp"
#include "manipulation/pick_place_job.hpp"
#include "manipulation/robot_frames.hpp"

namespace orthoflow::apps {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

struct GraspArgs {
  std::string frames;
  std::string objects;
  std::optional<std::uint64_t> frame;
  std::string model = "jaco2";
  std::vector<double> place;  // --place X,Y: where on the table (base frame) to put each object
  bool json = false;
};

nlohmann::json vec_json(const Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// --place: the pick-and-place job's joint-space poses, solved before anything would move, or the
// step the arm does not reach.
nlohmann::json job_json(std::uint64_t track, const manipulation::ObjectBox& box,
                        const manipulation::Grasp& grasp, const std::vector<double>& place,
                        const manipulation::GraspOptions& options) {
  manipulation::JobOptions job_options;
  job_options.grasp = options;
  const Vector3d centre = box.base_from_object.translation();
  const Vector3d to(place[0], place[1], centre.z());
  auto job = manipulation::make_pick_place_job(static_cast<std::uint32_t>(track), centre, grasp, to,
                                               job_options);
  if (!job.has_value()) return {{"refused", job.error()}};
  const manipulation::PickPlaceJob& j = job.value();
  return {{"place_m", vec_json(to)},         {"lift_joints_deg", j.lift},
          {"carry_joints_deg", j.carry},     {"place_joints_deg", j.place},
          {"retreat_joints_deg", j.retreat}, {"open_fingers", j.open_fingers},
          {"close_fingers", j.close_fingers}};
}

void run_grasp(const GraspArgs& a) {
  const PerceivedScene scene = load_perceived_scene("grasp", a.frames, a.objects, a.frame);
  const Isometry3d& x = scene.base_from_camera;
  const manipulation::PerceivedFrame& frame = scene.frame;
  const Vector3d& normal = scene.table.normal;
  const double offset = scene.table.offset;
  manipulation::GraspOptions options;
  options.table = scene.table;
  options.geometry =
      a.model == "v1" ? &drivers::jaco::jaco_v1_geometry() : &drivers::jaco::jaco2_geometry();
  nlohmann::json out = {{"frame", frame.frame},
                        {"table", {{"normal", vec_json(normal)}, {"offset_m", offset}}},
                        {"objects", nlohmann::json::array()}};
  std::size_t planned = 0;
  for (const manipulation::PerceivedObject& o : frame.objects) {
    nlohmann::json entry = {
        {"track", o.track},
        {"label", o.label.empty() ? nlohmann::json() : nlohmann::json(o.label)}};
    if (!o.truth.empty()) entry["truth"] = o.truth;
    if (!o.described) {
      entry["refused"] = "no object frame (not described)";
      out["objects"].push_back(entry);
      continue;
    }
    const manipulation::ObjectBox box = manipulation::object_box_in_base(x, o.frame, o.bbox);
    entry["centre_m"] = vec_json(box.base_from_object.translation());
    const auto plan = manipulation::plan_grasp(box, options);
    if (!plan.has_value()) {
      entry["refused"] = manipulation::to_string(plan.error());
      out["objects"].push_back(entry);
      continue;
    }
    const manipulation::GraspPlan& p = plan.value();
    entry["preferred"] = manipulation::to_string(p.preferred);
    entry["feasible"] = p.feasible_count;
    if (const manipulation::Grasp* g = p.best()) {
      ++planned;
      if (!a.place.empty()) entry["job"] = job_json(o.track, box, *g, a.place, options);
      entry["grasp"] = {{"kind", manipulation::to_string(g->kind)},
                        {"pre_grasp_m", vec_json(g->pre_grasp.translation())},
                        {"grasp_m", vec_json(g->grasp.translation())},
                        {"approach", vec_json(g->approach)},
                        {"width_m", g->width_m},
                        {"opening_m", g->opening_m},
                        {"pre_grasp_joints_deg", g->pre_grasp_joints},
                        {"grasp_joints_deg", g->grasp_joints},
                        {"joint_travel_deg", g->joint_travel_deg}};
    }
    nlohmann::json rejected = nlohmann::json::array();
    for (std::size_t i = 0; i < p.rejected_count; ++i) {
      rejected.push_back({{"kind", manipulation::to_string(p.rejected[i].kind)},
                          {"approach", vec_json(p.rejected[i].approach)},
                          {"width_m", p.rejected[i].width_m},
                          {"reason", manipulation::to_string(p.rejected[i].reason)}});
    }
    entry["rejected"] = rejected;
    out["objects"].push_back(entry);
  }
  out["planned"] = planned;
  if (a.json) {
    std::cout << out.dump() << '\n';
    return;
  }
  std::printf("frame %llu: %zu object(s), %zu with a grasp\n",
              static_cast<unsigned long long>(frame.frame), frame.objects.size(), planned);
  for (const auto& e : out["objects"]) {
    const std::string name =
        e["label"].is_string() ? e["label"].get<std::string>() : std::string("Unknown");
    std::printf(
        "track %llu (%s%s%s): ", static_cast<unsigned long long>(e["track"].get<std::uint64_t>()),
        name.c_str(), e.contains("truth") ? ", truth " : "",
        e.contains("truth") ? e["truth"].get<std::string>().c_str() : "");
    if (e.contains("refused")) {
      std::printf("no plan: %s\n", e["refused"].get<std::string>().c_str());
      continue;
    }
    if (e.contains("grasp")) {
      const auto& g = e["grasp"];
      std::printf(
          "%s grasp at [%.3f, %.3f, %.3f] m, pre-grasp [%.3f, %.3f, %.3f], width %.3f m, opening "
          "%.3f m\n",
          g["kind"].get<std::string>().c_str(), g["grasp_m"][0].get<double>(),
          g["grasp_m"][1].get<double>(), g["grasp_m"][2].get<double>(),
          g["pre_grasp_m"][0].get<double>(), g["pre_grasp_m"][1].get<double>(),
          g["pre_grasp_m"][2].get<double>(), g["width_m"].get<double>(),
          g["opening_m"].get<double>());
      if (e.contains("job")) {
        const auto& j = e["job"];
        if (j.contains("refused"))
          std::printf("    no job to the place: %s\n", j["refused"].get<std::string>().c_str());
        else
          std::printf("    job to [%.3f, %.3f]: lift, carry, place and retreat solved\n",
                      j["place_m"][0].get<double>(), j["place_m"][1].get<double>());
      }
    } else {
      std::printf("no feasible grasp\n");
    }
    for (const auto& r : e["rejected"]) {
      std::printf("    rejected %s grasp (width %.3f m): %s\n",
                  r["kind"].get<std::string>().c_str(), r["width_m"].get<double>(),
                  r["reason"].get<std::string>().c_str());
    }
  }
}

}  // namespace

void add_grasp_command(CLI::App& app) {
  auto a = std::make_shared<GraspArgs>();
  auto* cmd = app.add_subcommand(
      "grasp", "grasp plans, in the arm's base frame, of the objects of a run's JSON lines");
  cmd->add_option("--robot-frames", a->frames,
                  "robot frames file (orthoflow calibrate hand-eye --out)")
      ->required();
  cmd->add_option("--objects", a->objects, "JSON lines of orthoflow run --json-out")->required();
  cmd->add_option("--frame", a->frame, "frame id (default: the last frame with objects)");
  cmd->add_option("--model", a->model, "arm model: jaco2 or v1")
      ->check(CLI::IsMember({"jaco2", "v1"}));
  cmd->add_option("--place", a->place,
                  "X,Y on the table in the arm's base frame (m): also solve each grasped object's "
                  "pick-and-place job (lift, carry, place, retreat) in joint space")
      ->type_name("X,Y")  // signed: not the commands' non-negative rule (apps/option_checks.hpp)
      ->expected(2)
      ->delimiter(',')
      ->check(table_coordinate());
  cmd->add_flag("--json", a->json, "one JSON object on stdout");
  cmd->callback([a] { run_grasp(*a); });
}

}  // namespace orthoflow::apps
