// `orthoflow calibrate hand-eye --samples FILE [--model jaco2|v1] [--out FRAMES.yaml] [--json]`:
// the camera's pose in the arm's base frame from a samples file (manipulation/robot_frames.hpp:
// one JSON line per arm pose, with the target's pose or centre in the camera), by
// manipulation::solve_hand_eye; prints the transform and the residuals, names the worst sample,
// and writes the robot frames file `orthoflow grasp` reads.
//
// `orthoflow calibrate simulate-samples --out FILE [--count N] [--seed S] [--points]
// [--noise-mm M] [--noise-deg D] [--truth FRAMES.yaml]`: a samples file from a simulated rig (the
// JACO's forward kinematics at random poses around HOME, a camera at a known pose, Gaussian noise
// on the observations), with the true frames written to --truth, so the calibration can be tried
// and checked without a robot. It says that it is simulated in the file's first line.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/calibrate_target.hpp"
#include "apps/commands.hpp"
#include "core/file_output.hpp"
#include "manipulation/hand_eye.hpp"
#include "manipulation/robot_frames.hpp"

namespace orthoflow::apps {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

constexpr double DEG = std::numbers::pi / 180.0;

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow calibrate: " << message << '\n';
  throw CLI::RuntimeError(code);
}

const drivers::jaco::ArmGeometry& geometry_of(const std::string& model) {
  return model == "v1" ? drivers::jaco::jaco_v1_geometry() : drivers::jaco::jaco2_geometry();
}

nlohmann::json transform_json(const Isometry3d& t) {
  Eigen::Quaterniond q(t.linear());
  if (q.w() < 0.0) q.coeffs() *= -1.0;
  const drivers::jaco::CartesianPose pose = drivers::jaco::to_pose(t);
  return {{"translation_m", {t.translation().x(), t.translation().y(), t.translation().z()}},
          {"rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
          {"theta_rad", {pose.theta.x(), pose.theta.y(), pose.theta.z()}}};
}

struct HandEyeArgs {
  std::string samples;
  std::string model = "jaco2";
  std::string out;
  bool json = false;
};

void run_hand_eye(const HandEyeArgs& a) {
  std::ifstream in(a.samples);
  if (!in) fail(a.samples + ": cannot open", EXIT_BAD_INPUT);
  std::vector<manipulation::PoseSample> poses;
  std::vector<manipulation::PointSample> points;
  std::vector<std::size_t> line_of;  // sample index -> line number
  std::size_t number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    auto parsed = manipulation::parse_calibration_line(line, geometry_of(a.model));
    if (!parsed.has_value()) {
      fail(a.samples + ":" + std::to_string(number) + ": " + parsed.error(), EXIT_BAD_INPUT);
    }
    if (!parsed.value()) continue;
    if (const auto* p = std::get_if<manipulation::PoseSample>(&parsed.value()->sample)) {
      poses.push_back(*p);
    } else {
      points.push_back(std::get<manipulation::PointSample>(parsed.value()->sample));
    }
    line_of.push_back(number);
    if (!poses.empty() && !points.empty()) {
      fail(a.samples + ":" + std::to_string(number) +
               ": mixes target poses and target points; give one kind per file",
           EXIT_BAD_INPUT);
    }
  }
  const bool by_points = !points.empty();
  const auto solved =
      by_points ? manipulation::solve_hand_eye(std::span<const manipulation::PointSample>(points))
                : manipulation::solve_hand_eye(std::span<const manipulation::PoseSample>(poses));
  if (!solved.has_value()) {
    fail(a.samples + ": " + manipulation::to_string(solved.error()), EXIT_FAILURE_GENERIC);
  }
  const manipulation::HandEyeResult& r = solved.value();
  const std::size_t worst_line = line_of[r.worst_sample];
  // A sample far off the rest (five times the rms and over 5 mm) is most likely a bad observation.
  const bool outlier = r.max_position_m > 5.0 * r.rms_position_m && r.max_position_m > 0.005;
  nlohmann::json out = {{"samples", r.samples},
                        {"kind", by_points ? "target_point" : "target_pose"},
                        {"base_from_camera", transform_json(r.base_from_camera)},
                        {"gripper_from_target", transform_json(r.gripper_from_target)},
                        {"rms_position_mm", r.rms_position_m * 1e3},
                        {"max_position_mm", r.max_position_m * 1e3},
                        {"worst_line", worst_line},
                        {"likely_outlier", outlier},
                        {"iterations", r.iterations}};
  if (!by_points) out["rms_rotation_deg"] = r.rms_rotation_rad / DEG;
  if (!a.out.empty()) {
    char comment[256];
    std::snprintf(
        comment, sizeof comment,
        "written by orthoflow calibrate hand-eye from %s\n%zu samples, residual rms %.2f mm, max "
        "%.2f mm (line %zu)",
        a.samples.c_str(), r.samples, r.rms_position_m * 1e3, r.max_position_m * 1e3, worst_line);
    const auto text = manipulation::format_robot_frames({r.base_from_camera}, comment);
    if (auto w = core::write_whole_file(a.out, text); !w) fail(w.error(), EXIT_FAILURE_GENERIC);
    out["written"] = a.out;
  }
  if (a.json) {
    std::cout << out.dump() << '\n';
    return;
  }
  const Vector3d t = r.base_from_camera.translation();
  const auto& q = out["base_from_camera"]["rotation_wxyz"];
  std::printf("hand-eye from %zu %s samples (%d refinement steps)\n", r.samples,
              by_points ? "target-centre" : "target-pose", r.iterations);
  std::printf(
      "base_from_camera: translation [%.4f, %.4f, %.4f] m, rotation wxyz [%.6f, %.6f, %.6f, "
      "%.6f]\n",
      t.x(), t.y(), t.z(), q[0].get<double>(), q[1].get<double>(), q[2].get<double>(),
      q[3].get<double>());
  const Vector3d g = r.gripper_from_target.translation();
  std::printf("target in the gripper: [%.4f, %.4f, %.4f] m\n", g.x(), g.y(), g.z());
  std::printf("residual: rms %.2f mm, max %.2f mm (line %zu)", r.rms_position_m * 1e3,
              r.max_position_m * 1e3, worst_line);
  if (!by_points) std::printf(", rotation rms %.3f deg", r.rms_rotation_rad / DEG);
  std::printf("\n");
  if (outlier) {
    std::printf(
        "warning: line %zu is far off the others: check that observation and calibrate again\n",
        worst_line);
  }
  if (!a.out.empty()) std::printf("wrote %s\n", a.out.c_str());
}

struct SimulateArgs {
  std::string out;
  std::string truth;
  std::size_t count = 50;
  std::uint64_t seed = 1;
  bool points = false;
  double noise_mm = 1.0;
  double noise_deg = 0.2;
};

// The simulated rig: the camera of config/robot_frames_synthetic.yaml, a target 6 cm beyond the
// tool point.
void run_simulate(const SimulateArgs& a) {
  if (a.count == 0 || a.count > manipulation::HAND_EYE_MAX_SAMPLES) {
    fail("--count must be in [1, 4096]", EXIT_USAGE);
  }
  if (!(a.noise_mm >= 0.0) || !(a.noise_deg >= 0.0) || !std::isfinite(a.noise_mm) ||
      !std::isfinite(a.noise_deg)) {
    fail("--noise-mm and --noise-deg must be finite and not negative", EXIT_USAGE);
  }
  Isometry3d x = Isometry3d::Identity();
  x.linear() = Eigen::AngleAxisd(-135.0 * DEG, Vector3d::UnitX()).toRotationMatrix();
  x.translation() = Vector3d(0.0, -0.98994949366116658, 0.70710678118654746);
  Isometry3d y = Isometry3d::Identity();
  y.linear() = Eigen::AngleAxisd(20.0 * DEG, Vector3d::UnitX()).toRotationMatrix();
  y.translation() = Vector3d(0.0, 0.0, 0.06);
  std::mt19937_64 rng(a.seed);
  std::uniform_real_distribution<double> jog(-45.0, 45.0);
  std::normal_distribution<double> n(0.0, 1.0);
  std::ostringstream file;
  file << "# SIMULATED samples (orthoflow calibrate simulate-samples --seed " << a.seed
       << "): not a robot\n";
  for (std::size_t i = 0; i < a.count; ++i) {
    drivers::jaco::JointAngles q = drivers::jaco::HOME_JOINTS;
    for (double& v : q) v += jog(rng);
    const Isometry3d target = x.inverse() * drivers::jaco::forward_kinematics(q) * y;
    const Vector3d position =
        target.translation() + a.noise_mm * 1e-3 * Vector3d(n(rng), n(rng), n(rng));
    nlohmann::json line = {{"joints", q}};
    if (a.points) {
      line["target_point"] = {position.x(), position.y(), position.z()};
    } else {
      const Vector3d w(n(rng), n(rng), n(rng));
      Isometry3d noisy = target;
      noisy.linear() =
          target.linear() *
          Eigen::AngleAxisd(a.noise_deg * DEG * w.norm(), w.normalized()).toRotationMatrix();
      const auto pose = drivers::jaco::to_pose(noisy);
      line["target"] = {{"position", {position.x(), position.y(), position.z()}},
                        {"theta", {pose.theta.x(), pose.theta.y(), pose.theta.z()}}};
    }
    file << line.dump() << '\n';
  }
  if (auto w = core::write_whole_file(a.out, file.str()); !w) fail(w.error(), EXIT_FAILURE_GENERIC);
  if (!a.truth.empty()) {
    const auto truth =
        manipulation::format_robot_frames({x}, "the simulated rig's true camera pose");
    if (auto w = core::write_whole_file(a.truth, truth); !w) fail(w.error(), EXIT_FAILURE_GENERIC);
  }
  std::printf("wrote %zu simulated samples to %s\n", a.count, a.out.c_str());
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("calibrate",
                                 "robot calibration: the camera's pose in the arm's base frame");
  cmd->require_subcommand(1);

  auto h = std::make_shared<HandEyeArgs>();
  auto* he = cmd->add_subcommand(
      "hand-eye", "camera-to-arm-base transform from arm poses and target observations");
  he->add_option("--samples", h->samples,
                 "samples file: one JSON line per pose (manipulation/robot_frames.hpp)")
      ->required();
  he->add_option("--model", h->model, "arm model for joint readings: jaco2 or v1")
      ->check(CLI::IsMember({"jaco2", "v1"}));
  he->add_option("--out", h->out, "write the robot frames file (YAML) here");
  he->add_flag("--json", h->json, "one JSON object on stdout");
  he->callback([h] { run_hand_eye(*h); });

  auto s = std::make_shared<SimulateArgs>();
  auto* sim = cmd->add_subcommand(
      "simulate-samples", "a samples file from a simulated rig with a known camera (no robot)");
  sim->add_option("--out", s->out, "samples file to write")->required();
  sim->add_option("--truth", s->truth, "write the rig's true robot frames (YAML) here");
  sim->add_option("--count", s->count,
                  "arm poses, each joint within 45 degrees of HOME (default 50)");
  sim->add_option("--seed", s->seed, "random seed (default 1)");
  sim->add_flag("--points", s->points, "observe the target's centre only (a ball), not its pose");
  sim->add_option("--noise-mm", s->noise_mm,
                  "observation position noise per axis, standard deviation (default 1.0)");
  sim->add_option("--noise-deg", s->noise_deg,
                  "observation rotation noise per axis, standard deviation (default 0.2)");
  sim->callback([s] { run_simulate(*s); });

  add_calibrate_target_commands(cmd);
}

}  // namespace orthoflow::apps
