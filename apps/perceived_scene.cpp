#include "apps/perceived_scene.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "apps/commands.hpp"

namespace orthoflow::apps {

namespace {

[[noreturn]] void fail(const std::string& command, const std::string& message) {
  std::cerr << "orthoflow " << command << ": " << message << '\n';
  throw CLI::RuntimeError(EXIT_BAD_INPUT);
}

// The chosen frame of the run's JSON lines: the one @p frame names, else the last with objects.
manipulation::PerceivedFrame pick_frame(const std::string& command, const std::string& objects,
                                        std::optional<std::uint64_t> frame) {
  std::ifstream in(objects);
  if (!in) fail(command, objects + ": cannot open");
  std::optional<manipulation::PerceivedFrame> chosen;
  std::size_t number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    auto parsed = manipulation::parse_run_line(line);
    if (!parsed.has_value())
      fail(command, objects + ":" + std::to_string(number) + ": " + parsed.error());
    if (frame ? parsed.value().frame == *frame : !parsed.value().objects.empty()) {
      chosen = std::move(parsed.value());
      if (frame) break;
    }
  }
  if (!chosen)
    fail(command,
         objects + (frame ? ": no frame " + std::to_string(*frame) : ": no frame with objects"));
  if (!chosen->has_plane)
    fail(command, objects + ": frame " + std::to_string(chosen->frame) + " has no table plane");
  return *chosen;
}

}  // namespace

CLI::Validator table_coordinate() {
  return CLI::Validator(
      [](const std::string& v) {
        char* end = nullptr;
        const double x = std::strtod(v.c_str(), &end);
        return end != v.c_str() && *end == '\0' && std::isfinite(x) && std::fabs(x) <= 2.0
                   ? std::string()
                   : "'" + v + "' is not a coordinate in [-2, 2] m";
      },
      "M");
}

PerceivedScene load_perceived_scene(const std::string& command, const std::string& frames_file,
                                    const std::string& objects_file,
                                    std::optional<std::uint64_t> frame) {
  const auto frames = manipulation::load_robot_frames(frames_file);
  if (!frames.has_value()) fail(command, frames.error());
  PerceivedScene scene;
  scene.base_from_camera = frames.value().base_from_camera;
  scene.frame = pick_frame(command, objects_file, frame);
  // The plane in the base frame, its normal toward the camera's side (up).
  const Eigen::Isometry3d& x = scene.base_from_camera;
  Eigen::Vector3d normal = x.linear() * scene.frame.plane_normal;
  double offset = scene.frame.plane_d - normal.dot(x.translation());
  if (scene.frame.plane_d < 0.0) {
    normal = -normal;
    offset = -offset;
  }
  scene.table = {normal, offset};
  return scene;
}

}  // namespace orthoflow::apps
