// The arm's limits file (arm_limits_file.hpp): defaults, parsing and checking, the camera's box.
#include "manipulation/arm_limits_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "core/yaml_keys.hpp"

namespace orthoflow::manipulation {
namespace {

namespace jaco = drivers::jaco;
using Error = Unexpected<std::string>;

// The arm's reach with its hand: nothing of it is ever further than this from the base's axis.
constexpr double REACH_M = 1.0;

Error fail(const std::string& key, const std::string& why) { return err(key + ": " + why); }

Result<double, std::string> number(const YAML::Node& node, const std::string& key) {
  double x = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, x) || !std::isfinite(x))
    return fail(key, "not a finite number");
  return x;
}

Result<jaco::Box, std::string> box(const YAML::Node& node, const std::string& key,
                                   const std::string& name) {
  if (!node.IsSequence() || node.size() != 6) return fail(key, "needs [x0, y0, z0, x1, y1, z1]");
  std::array<double, 6> v{};
  for (std::size_t i = 0; i < 6; ++i) {
    auto x = number(node[i], key);
    if (!x) return err(x.error());
    v[i] = *x;
  }
  jaco::Box b;
  b.min = {v[0], v[1], v[2]};
  b.max = {v[3], v[4], v[5]};
  b.name.assign(name);
  if (!(b.min.array() < b.max.array()).all())
    return fail(key, "an inverted or empty box (each min must be below its max)");
  return b;
}

Result<jaco::BodyPart, std::string> part_named(const std::string& text, const std::string& key) {
  using P = jaco::BodyPart;
  for (const P p : {P::UPPER_ARM, P::FOREARM, P::WRIST_1, P::WRIST_2, P::WRIST_3, P::HAND,
                    P::FINGERTIPS, P::HELD_OBJECT})
    if (text == jaco::to_string(p)) return p;
  return fail(key, "'" + text + "' is not a part (upper_arm, forearm, wrist_1, ... hand)");
}

Result<void, std::string> add(jaco::SafetyLimits& limits, const jaco::Box& b) {
  if (limits.find_keep_out(b.name.view()) != nullptr)
    return fail("keep_out", "two boxes named '" + std::string(b.name.view()) + "'");
  if (!limits.add_keep_out(b))
    return fail("keep_out", "at most " + std::to_string(jaco::MAX_KEEP_OUT) + " boxes");
  return {};
}

// The table: everything of the workspace below the table's top.
jaco::Box table_box(const jaco::SafetyLimits& limits, double height) {
  jaco::Box b;
  b.min = {limits.workspace.min.x(), limits.workspace.min.y(), limits.workspace.min.z() - 0.1};
  b.max = {limits.workspace.max.x(), limits.workspace.max.y(), height};
  b.name.assign("table");
  return b;
}

// The base column, to keep the forearm and all past it away: JACO2's base is 0.09 m across.
jaco::Box base_box() {
  jaco::Box b{{-0.075, -0.075, -0.1}, {0.075, 0.075, 0.16}, core::FixedText<24>::from("base")};
  b.from = jaco::BodyPart::FOREARM;
  return b;
}

}  // namespace

ArmLimitsFile default_arm_limits() {
  ArmLimitsFile f;
  (void)add(f.limits, table_box(f.limits, f.table_height_m));
  (void)add(f.limits, base_box());
  return f;
}

namespace {

using Keys = std::set<std::string>;
const Keys KNOWN = {
    "table_height_m", "workspace_m", "keep_out",     "camera_half_extent_m", "camera_mount",
    "remove",         "speed_deg_s", "accel_deg_s2", "brake_decel_deg_s2",   "command_latency_ms"};

// A positive number no larger than @p most (what the hardware or the plausible allows).
Result<double, std::string> bounded(const YAML::Node& root, const std::string& key, double most) {
  auto x = number(root[key], key);
  if (!x) return x;
  if (!(*x > 0.0) || *x > most)
    return fail(key, "must lie in (0, " + std::to_string(most) +
                         "]: a larger value widens the "
                         "arm's documented range");
  return x;
}

Result<void, std::string> read_rates(const YAML::Node& root, ArmLimitsFile& f) {
  jaco::SafetyLimits& l = f.limits;
  const double hardware =
      *std::min_element(jaco::HARDWARE_SPEED_DEG_S.begin(), jaco::HARDWARE_SPEED_DEG_S.end());
  struct Rate {
    const char* key;
    double most;
    double* value;
  };
  for (const Rate& r : {Rate{"speed_deg_s", hardware, &l.max_joint_speed_deg_s},
                        Rate{"accel_deg_s2", 100.0, &l.max_joint_accel_deg_s2},
                        Rate{"brake_decel_deg_s2", 100.0, &l.brake_decel_deg_s2}}) {
    if (!root[r.key]) continue;
    auto x = bounded(root, r.key, r.most);
    if (!x) return err(x.error());
    *r.value = *x;
  }
  if (root["command_latency_ms"]) {
    auto ms = number(root["command_latency_ms"], "command_latency_ms");
    if (!ms) return err(ms.error());
    if (*ms < 10.0 || *ms > 1000.0)
      return fail("command_latency_ms", "must lie in [10, 1000] (at least the arm's period)");
    l.command_latency_ns = static_cast<std::int64_t>(*ms * 1e6);
  }
  if (l.brake_decel_deg_s2 < l.max_joint_accel_deg_s2)
    return fail("brake_decel_deg_s2",
                "below accel_deg_s2: the monitor would refuse the moves the "
                "arm is asked to brake in");
  return {};
}

Result<void, std::string> read_geometry(const YAML::Node& root, ArmLimitsFile& f) {
  if (root["table_height_m"]) {
    auto h = number(root["table_height_m"], "table_height_m");
    if (!h) return err(h.error());
    if (std::abs(*h) > 0.5) return fail("table_height_m", "must lie within 0.5 m of the base");
    f.table_height_m = *h;
  }
  if (root["workspace_m"]) {
    auto w = box(root["workspace_m"], "workspace_m", "workspace");
    if (!w) return err(w.error());
    const bool inside = (w->min.head<2>().array() >= -REACH_M).all() &&
                        (w->max.head<2>().array() <= REACH_M).all() && w->min.z() >= -0.5 &&
                        w->max.z() <= 1.3;
    if (!inside) return fail("workspace_m", "reaches past the arm's reach (1 m around the base)");
    f.limits.workspace = *w;
  }
  if (root["camera_half_extent_m"]) {
    const YAML::Node& n = root["camera_half_extent_m"];
    if (!n.IsSequence() || n.size() != 3) return fail("camera_half_extent_m", "needs [x, y, z]");
    for (int i = 0; i < 3; ++i) {
      auto x = number(n[i], "camera_half_extent_m");
      if (!x) return err(x.error());
      if (!(*x > 0.0) || *x > 1.0) return fail("camera_half_extent_m", "each in (0, 1] m");
      f.camera_half_extent_m[i] = *x;
    }
  }
  if (root["camera_mount"]) {
    if (!YAML::convert<bool>::decode(root["camera_mount"], f.camera_mount))
      return fail("camera_mount", "true or false");
  }
  return {};
}

Result<void, std::string> read_keep_outs(const YAML::Node& root, ArmLimitsFile& f) {
  if (root["remove"]) {
    if (!root["remove"].IsSequence()) return fail("remove", "a list of table, base, camera");
    for (const YAML::Node& n : root["remove"]) {
      const std::string name = n.IsScalar() ? n.as<std::string>() : "";
      if (name != "table" && name != "base" && name != "camera")
        return fail("remove", "'" + name + "' is not a default keep-out (table, base, camera)");
      f.removed.push_back(name);
    }
  }
  const auto removed = [&](const char* n) {
    return std::find(f.removed.begin(), f.removed.end(), n) != f.removed.end();
  };
  f.camera_removed = removed("camera");
  if (!removed("table")) (void)add(f.limits, table_box(f.limits, f.table_height_m));
  if (!removed("base")) (void)add(f.limits, base_box());
  if (!root["keep_out"]) return {};
  if (!root["keep_out"].IsSequence()) return fail("keep_out", "a list of boxes");
  for (const YAML::Node& n : root["keep_out"]) {
    if (!n.IsMap() || !n["name"] || !n["box_m"]) return fail("keep_out", "each needs name, box_m");
    for (const auto& kv : n) {
      const std::string k = kv.first.as<std::string>();
      if (k != "name" && k != "box_m" && k != "from") return fail("keep_out." + k, "unknown key");
    }
    const std::string name = n["name"].as<std::string>();
    if (name.empty() || name.size() > 23) return fail("keep_out.name", "1 to 23 characters");
    auto b = box(n["box_m"], "keep_out." + name + ".box_m", name);
    if (!b) return err(b.error());
    if (n["from"]) {
      auto p = part_named(n["from"].as<std::string>(), "keep_out." + name + ".from");
      if (!p) return err(p.error());
      b->from = *p;
    }
    if (auto ok = add(f.limits, *b); !ok) return ok;
  }
  return {};
}

}  // namespace

Result<ArmLimitsFile, std::string> parse_arm_limits(std::string_view yaml, std::string source) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::Exception& e) { return err(source + ": not YAML: " + e.what()); }
  if (auto unique = core::check_unique_keys(root); !unique)
    return err(source + ": " + unique.error().to_string());
  ArmLimitsFile f;
  f.source = source;
  if (!root.IsNull() && !root.IsMap()) return err(source + ": a map of keys is expected");
  const auto located = [&](Result<void, std::string> r) -> Result<void, std::string> {
    if (!r) return err(source + ": " + r.error());
    return {};
  };
  try {
    for (const auto& kv : root)
      if (!KNOWN.count(kv.first.as<std::string>()))
        return err(source + ": " + kv.first.as<std::string>() + ": unknown key");
    for (auto step : {read_rates, read_geometry, read_keep_outs})
      if (auto ok = located(step(root, f)); !ok) return err(ok.error());
  } catch (const YAML::Exception& e) { return err(source + ": " + e.what()); }
  return f;
}

}  // namespace orthoflow::manipulation
