// `orthoflow calibrate find-target --poses POSES.jsonl --radius R --out SAMPLES.jsonl [--json]`:
// for every line of the poses file ({"frame": "FILE.pcd", "joints": [6 actuator degrees]}, the
// frame relative to the poses file), finds the ball of radius R in the organized depth frame
// (kernels::SphereTargetFinder) and writes a samples line {"joints": ..., "target_point": ...} for
// `orthoflow calibrate hand-eye`; a frame without the ball is reported with the reason and left
// out. On a robot, `orthoflow run --source kinect --frames 1 --labels-out DIR` writes a frame and
// `orthoflow arm state --json` the joints (docs/MANIPULATION.md section 2).
//
// `orthoflow calibrate simulate-frames --out DIR [--count N] [--seed S] [--radius R] [--stick M]
// [--truth FRAMES.yaml]`: the same from a simulated rig (the demo's camera over the synthetic
// table, config/robot_frames_synthetic.yaml, the JACO 2's links drawn as capsules at random poses
// around HOME where the camera sees the ball's centre, a ball of radius R on a stick M beyond the
// tool point, the simulated Kinect's depth): DIR/poses.jsonl and DIR/pose_NNN.pcd.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/calibrate_target.hpp"
#include "apps/commands.hpp"
#include "core/file_output.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "formats/pcd_io.hpp"
#include "graphs/sessions/table_task_session.hpp"
#include "kernels/sphere_target.hpp"
#include "manipulation/arm_body.hpp"
#include "manipulation/robot_frames.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::apps {
namespace {

namespace fs = std::filesystem;
namespace jaco = drivers::jaco;
using Eigen::Isometry3d;
using Eigen::Vector3d;

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow calibrate: " << message << '\n';
  throw CLI::RuntimeError(code);
}

struct FindArgs {
  std::string poses;
  std::string out;
  double radius = 0.03;
  bool json = false;
};

struct Pose {
  fs::path frame;
  jaco::JointAngles joints{};
};

/// The poses file, every line checked before any frame is read.
std::vector<Pose> read_poses(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path + ": cannot open", EXIT_BAD_INPUT);
  std::vector<Pose> poses;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    const auto parsed = manipulation::parse_target_frame_line(line);
    if (!parsed) fail(path + ":" + std::to_string(number) + ": " + parsed.error(), EXIT_BAD_INPUT);
    if (!*parsed) continue;
    const fs::path frame = (*parsed)->frame;
    poses.push_back(
        {frame.is_absolute() ? frame : fs::path(path).parent_path() / frame, (*parsed)->joints});
    if (poses.size() > 4096) fail(path + ": more than 4096 poses", EXIT_BAD_INPUT);
  }
  if (poses.empty()) fail(path + ": no poses", EXIT_BAD_INPUT);
  return poses;
}

void run_find(const FindArgs& a) {
  if (!(a.radius >= 0.005 && a.radius <= 0.5))
    fail("--radius must be in [0.005, 0.5] m", EXIT_USAGE);
  const std::vector<Pose> poses = read_poses(a.poses);
  std::ostringstream out;
  out << "# orthoflow calibrate find-target --poses " << a.poses << " --radius " << a.radius
      << '\n';
  kernels::SphereTargetParams params;
  params.radius = static_cast<float>(a.radius);
  std::size_t found = 0;
  nlohmann::json report = nlohmann::json::array();
  std::unique_ptr<kernels::SphereTargetFinder> finder;
  for (const Pose& pose : poses) {
    nlohmann::json row = {{"frame", pose.frame.string()}};
    auto cloud = formats::read_pcd(pose.frame);
    if (!cloud) {
      row["refused"] = "cannot read: " + cloud.error().to_string();
    } else {
      if (!finder || cloud->size() > 640 * 480)
        finder = std::make_unique<kernels::SphereTargetFinder>(
            std::max<std::size_t>(cloud->size(), 640 * 480));
      const auto ball = finder->find(cloud->view(), params);
      if (!ball) {
        row["refused"] = ball.error();
      } else {
        ++found;
        row["centre_m"] = ball->centre;
        row["pixels"] = ball->pixels;
        row["rms_mm"] = ball->rms * 1e3;
        out << nlohmann::json{{"joints", pose.joints}, {"target_point", ball->centre}}.dump()
            << '\n';
      }
    }
    if (!a.json) {
      if (row.contains("refused")) {
        std::printf("%s: no ball (%s)\n", pose.frame.filename().c_str(),
                    row["refused"].get<std::string>().c_str());
      } else {
        std::printf("%s: ball at [%.4f, %.4f, %.4f] m, %zu pixels, rms %.2f mm\n",
                    pose.frame.filename().c_str(), row["centre_m"][0].get<double>(),
                    row["centre_m"][1].get<double>(), row["centre_m"][2].get<double>(),
                    row["pixels"].get<std::size_t>(), row["rms_mm"].get<double>());
      }
    }
    report.push_back(row);
  }
  if (auto w = core::write_whole_file(a.out, out.str()); !w) fail(w.error(), EXIT_FAILURE_GENERIC);
  if (a.json) {
    std::cout
        << nlohmann::json{{"poses", poses.size()}, {"found", found}, {"frames", report}}.dump()
        << '\n';
  } else {
    std::printf("the ball in %zu of %zu frames; samples in %s\n", found, poses.size(),
                a.out.c_str());
  }
  if (found == 0) fail("the ball was not found in any frame", EXIT_FAILURE_GENERIC);
}

struct SimulateFramesArgs {
  std::string out;
  std::string truth;
  std::size_t count = 40;
  std::uint64_t seed = 1;
  double radius = 0.03;
  double stick = 0.14;
};

void run_simulate_frames(const SimulateFramesArgs& a) {
  if (a.count == 0 || a.count > 1000) fail("--count must be in [1, 1000]", EXIT_USAGE);
  if (!(a.radius >= 0.01 && a.radius <= 0.1)) fail("--radius must be in [0.01, 0.1] m", EXIT_USAGE);
  if (!(a.stick >= a.radius + 0.08 && a.stick <= 0.5))
    fail("--stick must be in [radius + 0.08, 0.5] m (clear of the hand)", EXIT_USAGE);
  // The demo's rig: the camera over the synthetic table (config/robot_frames_synthetic.yaml).
  const Isometry3d base_from_camera = graphs::synthetic_base_from_camera(simulation::TableSpec{});
  Isometry3d gripper_from_ball = Isometry3d::Identity();
  gripper_from_ball.translation() = Vector3d(0.0, 0.0, a.stick);
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec || !fs::is_directory(a.out))
    fail(a.out + ": cannot create the directory", EXIT_FAILURE_GENERIC);
  std::ostringstream poses;
  poses << "# SIMULATED frames (orthoflow calibrate simulate-frames --seed " << a.seed
        << " --radius " << a.radius << " --stick " << a.stick << "): not a robot\n";
  std::mt19937_64 rng(a.seed);
  std::uniform_real_distribution<double> jog(-45.0, 45.0);
  const simulation::RenderOptions render{};
  const auto& k = render.intrinsics;
  kernels::PointCloud cloud;
  for (std::size_t i = 0, tries = 0; i < a.count; ++tries) {
    if (tries > 100 * a.count)
      fail("too few poses show the ball to the camera", EXIT_FAILURE_GENERIC);
    jaco::JointAngles q = jaco::HOME_JOINTS;
    for (double& v : q) v += jog(rng);
    const Vector3d c =
        (base_from_camera.inverse() * jaco::forward_kinematics(q) * gripper_from_ball)
            .translation();
    // An operator picks poses where the camera sees the ball: its centre inside the image, at
    // least a radius from the edge, 0.5-2 m away (the arm may still hide it).
    const double u = k.fx * c.x() / c.z() + k.cx, v = k.fy * c.y() / c.z() + k.cy;
    const double margin = k.fx * a.radius / std::max(c.z(), 1e-3);
    if (!(c.z() > 0.5 && c.z() < 2.0 && u > margin && v > margin && u < k.width - margin &&
          v < k.height - margin))
      continue;
    simulation::Scene scene;
    std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES> caps{};
    manipulation::ArmBodyModel body;
    body.margin_m = 0.0;
    const std::size_t n =
        manipulation::arm_body_capsules(q, base_from_camera, body, jaco::jaco2_geometry(), caps);
    for (std::size_t j = 0; j < n; ++j)
      scene.robot.push_back({{caps[j].a[0], caps[j].a[1], caps[j].a[2]},
                             {caps[j].b[0], caps[j].b[1], caps[j].b[2]},
                             caps[j].radius});
    scene.robot.push_back({{c.x(), c.y(), c.z()}, {c.x(), c.y(), c.z()}, a.radius});
    core::Rng noise(a.seed * 1000 + i);
    simulation::render_scene(scene, render, noise, cloud);
    char name[32];
    std::snprintf(name, sizeof name, "pose_%03zu.pcd", i);
    if (auto ok = formats::write_pcd(cloud, fs::path(a.out) / name); !ok)
      fail(std::string(name) + ": " + ok.error().to_string(), EXIT_FAILURE_GENERIC);
    poses << nlohmann::json{{"frame", name}, {"joints", q}}.dump() << '\n';
    ++i;
  }
  if (auto w = core::write_whole_file(fs::path(a.out) / "poses.jsonl", poses.str()); !w)
    fail(w.error(), EXIT_FAILURE_GENERIC);
  if (!a.truth.empty()) {
    const auto truth = manipulation::format_robot_frames({base_from_camera},
                                                         "the simulated rig's true camera pose");
    if (auto w = core::write_whole_file(a.truth, truth); !w) fail(w.error(), EXIT_FAILURE_GENERIC);
  }
  std::printf("wrote %zu simulated frames and %s/poses.jsonl\n", a.count, a.out.c_str());
}

}  // namespace

void add_calibrate_target_commands(CLI::App* cmd) {
  auto f = std::make_shared<FindArgs>();
  auto* find = cmd->add_subcommand(
      "find-target", "the ball in the gripper, found in depth frames: a samples file for hand-eye");
  find->add_option("--poses", f->poses,
                   "poses file: one JSON line per pose, {\"frame\": FILE.pcd, \"joints\": [6]}")
      ->required();
  find->add_option("--radius", f->radius, "the ball's radius in metres (default 0.03)");
  find->add_option("--out", f->out, "samples file to write")->required();
  find->add_flag("--json", f->json, "one JSON object on stdout");
  find->callback([f] { run_find(*f); });

  auto s = std::make_shared<SimulateFramesArgs>();
  auto* sim = cmd->add_subcommand(
      "simulate-frames", "depth frames of a ball in the gripper from a simulated rig (no robot)");
  sim->add_option("--out", s->out, "directory for poses.jsonl and the frames")->required();
  sim->add_option("--truth", s->truth, "write the rig's true robot frames (YAML) here");
  sim->add_option("--count", s->count, "frames (default 40)");
  sim->add_option("--seed", s->seed, "random seed (default 1)");
  sim->add_option("--radius", s->radius, "the ball's radius in metres (default 0.03)");
  sim->add_option("--stick", s->stick,
                  "the ball's centre beyond the tool point, metres (default 0.14)");
  sim->callback([s] { run_simulate_frames(*s); });
}

}  // namespace orthoflow::apps
