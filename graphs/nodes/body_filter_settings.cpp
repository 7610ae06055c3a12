// The body_filter kind's configuration (graphs/nodes/body_filter_node.hpp): its parameters parsed
// into its settings (the instructor zones, the robot frames, the arm), and the node put into a
// graph in front of preprocess. The node itself is in body_filter_node.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "graphs/nodes/body_filter_node.hpp"
#include "graphs/nodes/body_filter_settings.hpp"
#include "manipulation/robot_frames.hpp"

namespace orthoflow::graphs {

namespace {

using engine::ParamMap;

/// `exclude`: "ax,ay,az,bx,by,bz,r" capsules in the camera frame (metres), separated by ';'.
Result<void, std::string> parse_zones(const std::string& text, BodyFilterSettings& s) {
  const std::string what = "body_filter: exclude: ";
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    const std::string zone = text.substr(start, end - start);
    start = end + 1;
    if (s.zone_count == MAX_ZONES)
      return err(what + "at most " + std::to_string(MAX_ZONES) + " zones");
    std::array<double, 7> v{};
    const char* p = zone.c_str();
    for (std::size_t k = 0; k < v.size(); ++k) {
      char* next = nullptr;
      v[k] = std::strtod(p, &next);
      if (next == p || !std::isfinite(v[k]))
        return err(what + "'" + zone + "' is not ax,ay,az,bx,by,bz,radius (7 numbers, metres)");
      p = next;
      while (*p == ' ') ++p;
      if (k + 1 < v.size() && *p++ != ',')
        return err(what + "'" + zone + "' is not ax,ay,az,bx,by,bz,radius (7 numbers, metres)");
    }
    if (*p != '\0') return err(what + "'" + zone + "' has more than 7 numbers");
    if (!(v[6] > 0.0 && v[6] <= 2.0)) return err(what + "a radius must be in (0, 2] m");
    kernels::Capsule& c = s.zones[s.zone_count++];
    c.a = {float(v[0]), float(v[1]), float(v[2])};
    c.b = {float(v[3]), float(v[4]), float(v[5])};
    c.radius = float(v[6]);
  }
  return {};
}

/// "tx,ty,tz,qw,qx,qy,qz" as a robot frames file's base_from_camera (the same checks).
Result<manipulation::RobotFrames, std::string> parse_inline_frames(const std::string& text) {
  std::vector<std::string> v;
  std::size_t start = 0;
  for (std::size_t comma; (comma = text.find(',', start)) != std::string::npos; start = comma + 1)
    v.push_back(text.substr(start, comma - start));
  v.push_back(text.substr(start));
  if (v.size() != 7)
    return err("base_from_camera: '" + text + "' is not 7 numbers tx,ty,tz,qw,qx,qy,qz");
  return manipulation::parse_robot_frames("base_from_camera:\n  translation_m: [" + v[0] + ", " +
                                          v[1] + ", " + v[2] + "]\n  rotation_wxyz: [" + v[3] +
                                          ", " + v[4] + ", " + v[5] + ", " + v[6] + "]\n");
}

}  // namespace

Result<BodyFilterSettings, std::string> parse_body_filter_settings(const ParamMap& params) {
  if (auto ok = params.only({"robot_frames", "base_from_camera", "state", "state_topic",
                             "max_state_age_ms", "margin", "arm", "exclude"});
      !ok)
    return err(ok.error());
  BodyFilterSettings s;
  auto exclude = params.text("exclude", "");
  if (!exclude) return err(exclude.error());
  if (auto ok = parse_zones(*exclude, s); !ok) return err(ok.error());
  auto arm = params.choice("arm", "jaco2", {"jaco2", "jaco_v1", "none"});
  if (!arm) return err(arm.error());
  s.arm = *arm != "none";
  s.geometry =
      *arm == "jaco_v1" ? &drivers::jaco::jaco_v1_geometry() : &drivers::jaco::jaco2_geometry();
  if (!s.arm) {
    if (params.has("robot_frames") || params.has("base_from_camera") || params.has("state") ||
        params.has("state_topic"))
      return err(std::string(
          "body_filter: arm none takes no robot_frames, base_from_camera, state or state_topic"));
    if (s.zone_count == 0)
      return err(std::string("body_filter: arm none needs exclude zones (else it does nothing)"));
    return s;
  }
  auto path = params.text("robot_frames", "");
  if (!path) return err(path.error());
  auto inline_frames = params.text("base_from_camera", "");
  if (!inline_frames) return err(inline_frames.error());
  if (path->empty() == inline_frames->empty())
    return err(
        std::string("body_filter: give exactly one of robot_frames (the robot frames file) and "
                    "base_from_camera (tx,ty,tz,qw,qx,qy,qz)"));
  auto frames =
      path->empty() ? parse_inline_frames(*inline_frames) : manipulation::load_robot_frames(*path);
  if (!frames) return err("body_filter: " + frames.error());
  s.base_from_camera = frames->base_from_camera;
  auto age = params.number("max_state_age_ms", 50.0, 1.0, 1000.0);
  if (!age) return err(age.error());
  s.max_state_age_ns = static_cast<std::int64_t>(*age * 1e6);
  auto margin = params.number("margin", s.model.margin_m, 0.0, 0.2);
  if (!margin) return err(margin.error());
  s.model.margin_m = *margin;
  return s;
}

Result<void, std::string> insert_body_filter(engine::GraphSpec& spec,
                                             const engine::ParamMap& params) {
  const engine::NodeSpec* preprocess = nullptr;
  for (const engine::NodeSpec& node : spec.nodes) {
    if (node.name == "body") return err(std::string("the graph already has a node named body"));
    if (node.kind == "preprocess") preprocess = &node;
  }
  if (preprocess == nullptr)
    return err(
        std::string("the robot-body filter goes in front of preprocess: the graph has none"));
  engine::EdgeSpec* into = nullptr;
  for (engine::EdgeSpec& edge : spec.edges) {
    if (edge.to_node != preprocess->name) continue;
    if (into != nullptr)
      return err("the robot-body filter needs exactly one edge into " + preprocess->name);
    into = &edge;
  }
  if (into == nullptr) return err("nothing feeds " + preprocess->name);
  engine::EdgeSpec out{"body", "out", into->to_node, into->to_port, into->line};
  into->to_node = "body";
  into->to_port = "in";
  spec.edges.push_back(out);
  engine::NodeSpec body;
  body.name = "body";
  body.kind = "body_filter";
  body.params = params;
  body.ordered = true;
  spec.nodes.push_back(body);
  return {};
}

}  // namespace orthoflow::graphs
