// The ORTHOFLOW_SIM_KINECT syntax (sim_kinect_env.hpp): Kinects split on ';', keys on ',', '='.
#include "tests/support/sim_libusb/sim_kinect_env.hpp"
#include "tests/support/sim_libusb/env_text.hpp"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <set>
#include <utility>

namespace orthoflow::sim_libusb {
namespace {

using simulation::KinectModel;
using simulation::SimKinectConfig;
using Kinects = std::vector<SimKinectConfig>;

using env_text::parse_number;
using env_text::parse_rate;
using env_text::split;
using env_text::trim;

std::string default_serial(std::size_t index) {
  if (index == 0) return "A00364A11700045A";
  static constexpr char HEX[] = "0123456789ABCDEF";
  return std::string("A00364A11700045") + HEX[index % 16];
}

// One Kinect's "key=value,..." onto c; returns an error message or "".
std::string parse_one(std::string_view entry, SimKinectConfig& c) {
  if (entry.empty()) return "";
  for (const std::string_view item : split(entry, ',')) {
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) return "'" + std::string(item) + "' is not key=value";
    const std::string_view key = trim(item.substr(0, eq));
    const std::string_view value = trim(item.substr(eq + 1));
    const std::string bad = "bad value '" + std::string(value) + "' for " + std::string(key);
    if (key == "model") {
      if (value == "1414") {
        c.model = KinectModel::K1414;
      } else if (value == "1473") {
        c.model = KinectModel::K1473;
      } else if (value == "k4w" || value == "K4W") {
        c.model = KinectModel::K4W;
      } else {
        return bad + " (1414, 1473 or k4w)";
      }
    } else if (key == "serial") {
      const bool printable =
          std::all_of(value.begin(), value.end(), [](char ch) { return ch > ' ' && ch < 0x7F; });
      if (value.size() != 16 || !printable) return bad + " (16 printable characters)";
      c.serial = std::string(value);
    } else if (key == "seed") {
      if (!parse_number(value, c.scene_seed)) return bad;
    } else if (key == "fault_seed") {
      if (!parse_number(value, c.fault_seed)) return bad;
    } else if (key == "bus") {
      unsigned bus = 0;
      if (!parse_number(value, bus) || bus < 1 || bus > 255) return bad + " (1..255)";
      c.bus = static_cast<std::uint8_t>(bus);
    } else if (key == "ports") {
      std::vector<std::uint8_t> ports;
      for (const std::string_view p : split(value, '.')) {
        unsigned port = 0;
        if (!parse_number(p, port) || port < 1 || port > 15) return bad + " (ports of 1..15)";
        ports.push_back(static_cast<std::uint8_t>(port));
      }
      if (ports.size() > 6) return bad + " (at most 6 ports)";
      c.hub_ports = std::move(ports);
    } else if (key == "audio") {
      if (value != "0" && value != "1") return bad + " (0 or 1)";
      c.with_audio = value == "1";
    } else if (key == "depth") {
      if (value == "ramp") {
        c.depth_source = ramp_depth;
      } else if (value == "scene") {
        c.depth_source = {};
      } else {
        return bad + " (scene or ramp)";
      }
    } else if (key == "drop") {
      if (!parse_rate(value, c.faults.packets.drop_rate)) return bad + " (a rate in [0, 1])";
    } else if (key == "duplicate") {
      if (!parse_rate(value, c.faults.packets.duplicate_rate)) return bad + " (a rate in [0, 1])";
    } else if (key == "corrupt") {
      if (!parse_rate(value, c.faults.packets.corrupt_rate)) return bad + " (a rate in [0, 1])";
    } else if (key == "reorder") {
      if (!parse_rate(value, c.faults.packets.reorder_rate)) return bad + " (a rate in [0, 1])";
    } else {
      return "unknown key '" + std::string(key) + "'";
    }
  }
  return "";
}

}  // namespace

void ramp_depth(std::uint64_t frame, std::span<std::uint16_t> raw) noexcept {
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const std::uint64_t x = i % 640;
    const std::uint64_t y = i / 640;
    raw[i] = static_cast<std::uint16_t>(300 + (x + 2 * y + 13 * frame) % 1500);
  }
}

Result<Kinects, std::string> parse_kinects(std::string_view text) {
  try {
    Kinects kinects;
    text = trim(text);
    if (text.empty()) {
      kinects.emplace_back();
      return kinects;
    }
    if (text == "none") return kinects;  // no Kinect at all (e.g. an ORTHOFLOW_SIM_JACO arm alone)
    const std::vector<std::string_view> entries = split(text, ';');
    for (std::size_t k = 0; k < entries.size(); ++k) {
      SimKinectConfig c;
      c.serial = default_serial(k);
      c.hub_ports = {static_cast<std::uint8_t>(k % 15 + 1)};
      const std::string problem = parse_one(entries[k], c);
      if (!problem.empty()) return orthoflow::err("Kinect " + std::to_string(k) + ": " + problem);
      kinects.push_back(std::move(c));
    }
    std::set<std::string> serials;
    std::set<std::pair<std::uint8_t, std::vector<std::uint8_t>>> hubs;
    for (std::size_t k = 0; k < kinects.size(); ++k) {
      if (!serials.insert(kinects[k].serial).second)
        return orthoflow::err("Kinect " + std::to_string(k) + ": serial " + kinects[k].serial +
                              " is used twice");
      if (!hubs.insert({kinects[k].bus, kinects[k].hub_ports}).second)
        return orthoflow::err("Kinect " + std::to_string(k) +
                              ": two Kinects on the same bus and hub ports");
    }
    return kinects;
  } catch (const std::exception& e) {
    return orthoflow::err(std::string("cannot parse: ") + e.what());
  }
}

Result<bool, std::string> parse_pace(std::string_view text) {
  text = trim(text);
  if (text.empty() || text == "realtime") return true;
  if (text == "max") return false;
  return orthoflow::err("bad value '" + std::string(text) + "' (realtime or max)");
}

Result<Kinects, std::string> kinects_from_env() {
  const char* text = std::getenv(ENV_KINECT);
  return parse_kinects(text == nullptr ? std::string_view{} : std::string_view(text));
}

}  // namespace orthoflow::sim_libusb
