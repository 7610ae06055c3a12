#include "apps/graph_overrides.hpp"

#include <cmath>
#include <cstdlib>
#include <string_view>

namespace orthoflow::apps {

namespace {
engine::NodeSpec* find_kind(engine::GraphSpec& spec, std::string_view kind) {
  for (auto& node : spec.nodes) {
    if (node.kind == kind) return &node;
  }
  return nullptr;
}
}  // namespace

Result<void, std::string> apply_source(engine::GraphSpec& spec, const std::string& source,
                                       std::uint64_t frames) {
  engine::NodeSpec* src = find_kind(spec, "synthetic_source");
  if (src == nullptr) src = find_kind(spec, "pcd_source");
  if (src == nullptr) src = find_kind(spec, "kinect_source");
  if (src == nullptr) src = find_kind(spec, "replay_source");
  if (src == nullptr) src = find_kind(spec, "tum_source");
  if (src == nullptr) {
    if (!source.empty())
      return err(
          std::string("--source needs a graph whose source is synthetic_source, pcd_source, "
                      "kinect_source, replay_source or tum_source"));
    return {};
  }
  if (source.rfind("pcd:", 0) == 0) {
    src->kind = "pcd_source";
    src->params = {};
    src->params.assign("dir", source.substr(4));
  } else if (source.rfind("synthetic:", 0) == 0) {
    src->kind = "synthetic_source";
    src->params.assign("seed", source.substr(10));
  } else if (source == "kinect" || source.rfind("kinect:", 0) == 0) {
    src->kind = "kinect_source";
    src->params = {};
    src->params.assign("device", "usb");
    if (source.size() > 7) src->params.assign("serial", source.substr(7));
  } else if (source == "kinect-sim" || source.rfind("kinect-sim:", 0) == 0) {
    src->kind = "kinect_source";
    src->params = {};
    src->params.assign("device", "sim");
    if (source.size() > 11) src->params.assign("sim_seed", source.substr(11));
  } else if (source.rfind("replay:", 0) == 0) {
    src->kind = "replay_source";
    src->params = {};
    src->params.assign("dir", source.substr(7));
    spec.period_ns = 0;  // the recording's own pace (replay_source pace=recorded) unless --rate
  } else if (source.rfind("tum:", 0) == 0) {
    src->kind = "tum_source";
    src->params = {};
    src->params.assign("dir", source.substr(4));
    spec.period_ns = 0;  // the recording's own pace (tum_source pace=recorded) unless --rate
  } else if (source.rfind("world:", 0) == 0) {
    // The closed-loop world the process supplies (apps/cmd_run.cpp:
    // graphs/sessions/arm_world_feed.hpp).
    src->kind = "world_source";
    src->params = {};
  } else if (!source.empty()) {
    return err(
        "--source must be synthetic:SEED, pcd:DIR, kinect[:SERIAL], kinect-sim[:SEED], "
        "replay:DIR, tum:DIR or world:SEED, not '" +
        source + "'");
  }
  if (frames > 0 && src->kind == "synthetic_source")
    src->params.assign("frames", std::to_string(frames));
  return {};
}

std::string check_rate(const std::string& v) {
  // The whole text is the number ("5abc" is not 5), and the period 1e9 / rate must stay a sane
  // int64 of nanoseconds: 0.01 Hz (100 s) to 1000 Hz.
  if (v == "max") return std::string();
  char* end = nullptr;
  const double hz = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(hz)) {
    return std::string("rate must be a number of Hz or max, not '" + v + "'");
  }
  return hz >= 0.01 && hz <= 1000.0 ? std::string()
                                    : std::string("rate must be in [0.01, 1000] Hz or max");
}

void apply_rate(engine::GraphSpec& spec, const std::string& rate) {
  if (rate.empty()) return;
  // A replay at a given rate (or max) is paced by the engine, not by the recorded times.
  for (const char* kind : {"replay_source", "tum_source"}) {
    if (engine::NodeSpec* replay = find_kind(spec, kind)) replay->params.assign("pace", "max");
  }
  spec.period_ns = rate == "max" ? 0 : static_cast<std::int64_t>(1e9 / std::stod(rate));
}

}  // namespace orthoflow::apps
