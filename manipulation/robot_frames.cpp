#include "manipulation/robot_frames.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include "core/yaml_keys.hpp"

namespace orthoflow::manipulation {
namespace {

constexpr double UNIT_TOLERANCE = 1e-3;
constexpr std::size_t MAX_FRAMES_BYTES = 64 * 1024;
constexpr std::size_t MAX_LINE_BYTES = 4096;

// A YAML sequence of exactly n finite numbers.
Result<std::vector<double>, std::string> numbers(const YAML::Node& node, std::size_t n,
                                                 const char* key) {
  if (!node || !node.IsSequence() || node.size() != n) {
    return err(std::string(key) + ": expected a list of " + std::to_string(n) + " numbers");
  }
  std::vector<double> out;
  for (const YAML::Node& v : node) {
    double x = 0.0;
    if (!v.IsScalar() || !YAML::convert<double>::decode(v, x) || !std::isfinite(x)) {
      return err(std::string(key) + ": '" + (v.IsScalar() ? v.Scalar() : std::string("?")) +
                 "' is not a finite number");
    }
    out.push_back(x);
  }
  return out;
}

// A JSON array of exactly n finite numbers.
Result<Eigen::Vector3d, std::string> vec3(const nlohmann::json& j, const char* key) {
  if (!j.is_array() || j.size() != 3) { return err(std::string(key) + ": expected [x, y, z]"); }
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    if (!j[static_cast<std::size_t>(k)].is_number() ||
        !std::isfinite(j[static_cast<std::size_t>(k)].get<double>())) {
      return err(std::string(key) + ": element " + std::to_string(k) + " is not a finite number");
    }
    v[k] = j[static_cast<std::size_t>(k)].get<double>();
  }
  return v;
}

Result<Eigen::Isometry3d, std::string> pose_of(const nlohmann::json& j, const char* key) {
  if (!j.is_object() || !j.contains("position") || !j.contains("theta")) {
    return err(std::string(key) + ": expected {\"position\": [x,y,z], \"theta\": [tx,ty,tz]}");
  }
  const auto position = vec3(j["position"], (std::string(key) + ".position").c_str());
  if (!position.has_value()) { return err(position.error()); }
  const auto theta = vec3(j["theta"], (std::string(key) + ".theta").c_str());
  if (!theta.has_value()) { return err(theta.error()); }
  return drivers::jaco::to_transform({position.value(), theta.value()});
}

}  // namespace

Result<RobotFrames, std::string> parse_robot_frames(std::string_view yaml) {
  if (yaml.size() > MAX_FRAMES_BYTES) {
    return err(std::string("robot frames: larger than 64 KiB"));
  }
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::Exception& e) {
    return err("robot frames: not YAML (line " + std::to_string(e.mark.line + 1) + "): " + e.msg);
  }
  if (auto unique = core::check_unique_keys(root); !unique)
    return err("robot frames: " + unique.error().to_string());
  if (!root.IsMap() || !root["base_from_camera"] || !root["base_from_camera"].IsMap()) {
    return err(std::string(
        "robot frames: expected a map with base_from_camera: {translation_m, rotation_wxyz}"));
  }
  const YAML::Node node = root["base_from_camera"];
  const auto t = numbers(node["translation_m"], 3, "base_from_camera.translation_m");
  if (!t.has_value()) { return err("robot frames: " + t.error()); }
  const auto q = numbers(node["rotation_wxyz"], 4, "base_from_camera.rotation_wxyz");
  if (!q.has_value()) { return err("robot frames: " + q.error()); }
  Eigen::Quaterniond quaternion(q.value()[0], q.value()[1], q.value()[2], q.value()[3]);
  const double norm = quaternion.norm();
  if (std::abs(norm - 1.0) > UNIT_TOLERANCE) {
    std::ostringstream message;
    message << "robot frames: base_from_camera.rotation_wxyz has norm " << norm
            << ", not a unit quaternion";
    return err(message.str());
  }
  quaternion.normalize();
  RobotFrames frames;
  frames.base_from_camera.linear() = quaternion.toRotationMatrix();
  frames.base_from_camera.translation() = Eigen::Vector3d(t.value()[0], t.value()[1], t.value()[2]);
  return frames;
}

Result<RobotFrames, std::string> load_robot_frames(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) { return err(path + ": cannot open"); }
  std::string text(MAX_FRAMES_BYTES + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  auto frames = parse_robot_frames(text);
  if (!frames.has_value()) { return err(path + ": " + frames.error()); }
  return frames;
}

std::string format_robot_frames(const RobotFrames& frames, std::string_view comment) {
  std::ostringstream out;
  std::istringstream lines{std::string(comment)};
  for (std::string line; std::getline(lines, line);) { out << "# " << line << '\n'; }
  Eigen::Quaterniond q(frames.base_from_camera.linear());
  if (q.w() < 0.0) {
    q.coeffs() *= -1.0;  // the same rotation; w >= 0 reads more easily
  }
  const Eigen::Vector3d t = frames.base_from_camera.translation();
  out << std::setprecision(17);
  out << "base_from_camera:\n  translation_m: [" << t.x() << ", " << t.y() << ", " << t.z() << "]\n"
      << "  rotation_wxyz: [" << q.w() << ", " << q.x() << ", " << q.y() << ", " << q.z() << "]\n";
  return out.str();
}

namespace {

/// One line of a JSON-lines file: nullopt for a blank or comment line, the object otherwise; the
/// error for a line too long or not a JSON object.
Result<std::optional<nlohmann::json>, std::string> json_line(std::string_view line) {
  const auto first = line.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos || line[first] == '#') {
    return std::optional<nlohmann::json>{};
  }
  if (line.size() > MAX_LINE_BYTES) { return err(std::string("longer than 4096 bytes")); }
  nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
  if (j.is_discarded() || !j.is_object()) { return err(std::string("not a JSON object")); }
  return std::optional<nlohmann::json>{std::move(j)};
}

}  // namespace

Result<std::optional<TargetFrameLine>, std::string> parse_target_frame_line(std::string_view line) {
  auto object = json_line(line);
  if (!object) return err(object.error());
  if (!*object) return std::optional<TargetFrameLine>{};
  const nlohmann::json& j = **object;
  if (!j.contains("frame") || !j["frame"].is_string() || j["frame"].get<std::string>().empty() ||
      j["frame"].get<std::string>().find('\0') != std::string::npos) {
    return err(std::string("'frame' must name a PCD file"));
  }
  if (!j.contains("joints") || !j["joints"].is_array() || j["joints"].size() != 6) {
    return err(std::string("'joints' must be 6 actuator angles in degrees"));
  }
  TargetFrameLine out;
  out.frame = j["frame"].get<std::string>();
  for (std::size_t k = 0; k < 6; ++k) {
    const nlohmann::json& v = j["joints"][k];
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      return err("'joints': element " + std::to_string(k) + " is not a finite number");
    }
    out.joints[k] = v.get<double>();
  }
  return std::optional<TargetFrameLine>{std::move(out)};
}

Result<std::optional<CalibrationLine>, std::string> parse_calibration_line(
    std::string_view line, const drivers::jaco::ArmGeometry& geometry) {
  auto object = json_line(line);
  if (!object) return err(object.error());
  if (!*object) return std::optional<CalibrationLine>{};
  const nlohmann::json& j = **object;
  Eigen::Isometry3d base_from_gripper;
  if (j.contains("joints") == j.contains("gripper")) {
    return err(std::string("give exactly one of \"joints\" and \"gripper\""));
  }
  if (j.contains("joints")) {
    const nlohmann::json& q = j["joints"];
    if (!q.is_array() || q.size() != 6) {
      return err(std::string("joints: expected 6 actuator angles in degrees"));
    }
    drivers::jaco::JointAngles angles{};
    for (std::size_t k = 0; k < 6; ++k) {
      if (!q[k].is_number() || !std::isfinite(q[k].get<double>())) {
        return err("joints: element " + std::to_string(k) + " is not a finite number");
      }
      angles[k] = q[k].get<double>();
    }
    base_from_gripper = drivers::jaco::forward_kinematics(angles, geometry);
  } else {
    auto pose = pose_of(j["gripper"], "gripper");
    if (!pose.has_value()) { return err(pose.error()); }
    base_from_gripper = pose.value();
  }
  if (j.contains("target") == j.contains("target_point")) {
    return err(std::string("give exactly one of \"target\" and \"target_point\""));
  }
  if (j.contains("target")) {
    auto pose = pose_of(j["target"], "target");
    if (!pose.has_value()) { return err(pose.error()); }
    return std::optional<CalibrationLine>{
        CalibrationLine{PoseSample{base_from_gripper, pose.value()}}};
  }
  auto point = vec3(j["target_point"], "target_point");
  if (!point.has_value()) { return err(point.error()); }
  return std::optional<CalibrationLine>{
      CalibrationLine{PointSample{base_from_gripper, point.value()}}};
}

Result<PerceivedFrame, std::string> parse_run_line(std::string_view line) {
  const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
  if (j.is_discarded() || !j.is_object()) { return err(std::string("not a JSON object")); }
  PerceivedFrame out;
  if (j.contains("frame") && j["frame"].is_number_unsigned()) {
    out.frame = j["frame"].get<std::uint64_t>();
  }
  if (j.contains("plane") && j["plane"].is_object() && j["plane"].contains("normal") &&
      j["plane"].contains("d")) {
    const auto normal = vec3(j["plane"]["normal"], "plane.normal");
    if (!normal.has_value()) { return err(normal.error()); }
    if (!j["plane"]["d"].is_number() || !std::isfinite(j["plane"]["d"].get<double>())) {
      return err(std::string("plane.d: not a finite number"));
    }
    out.has_plane = true;
    out.plane_normal = normal.value();
    out.plane_d = j["plane"]["d"].get<double>();
  }
  if (!j.contains("objects")) { return out; }
  if (!j["objects"].is_array()) { return err(std::string("objects: not a list")); }
  std::size_t index = 0;
  for (const nlohmann::json& o : j["objects"]) {
    const std::string where = "objects[" + std::to_string(index++) + "]";
    if (!o.is_object()) { return err(where + ": not an object"); }
    PerceivedObject p;
    if (o.contains("track") && o["track"].is_number_unsigned()) {
      p.track = o["track"].get<std::uint64_t>();
    }
    if (o.contains("label") && o["label"].is_string()) { p.label = o["label"].get<std::string>(); }
    if (o.contains("truth") && o["truth"].is_string()) { p.truth = o["truth"].get<std::string>(); }
    if (o.contains("frame") && o.contains("bbox")) {
      const nlohmann::json& f = o["frame"];
      const nlohmann::json& b = o["bbox"];
      if (!f.is_array() || f.size() != 16 || !b.is_array() || b.size() != 3) {
        return err(where + ": frame must hold 16 numbers and bbox 3");
      }
      for (std::size_t k = 0; k < 16; ++k) {
        if (!f[k].is_number()) {
          return err(where + ".frame: element " + std::to_string(k) + " is not a number");
        }
        p.frame[k] = f[k].get<float>();
      }
      for (std::size_t k = 0; k < 3; ++k) {
        if (!b[k].is_number()) {
          return err(where + ".bbox: element " + std::to_string(k) + " is not a number");
        }
        p.bbox[k] = b[k].get<float>();
      }
      p.described = true;
    }
    out.objects.push_back(std::move(p));
  }
  return out;
}

}  // namespace orthoflow::manipulation
