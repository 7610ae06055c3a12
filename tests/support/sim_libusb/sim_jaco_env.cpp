// The ORTHOFLOW_SIM_JACO syntax (sim_jaco_env.hpp): arms split on ';', keys on ',', '='.
#include "tests/support/sim_libusb/sim_jaco_env.hpp"
#include "tests/support/sim_libusb/env_text.hpp"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <set>
#include <utility>

namespace orthoflow::sim_libusb {
namespace {

using drivers::jaco::ArmState;
using simulation::SimJacoConfig;
using Jacos = std::vector<SimJacoConfig>;

using env_text::parse_number;
using env_text::parse_rate;
using env_text::split;
using env_text::trim;

bool printable(std::string_view s, std::size_t max) noexcept {
  return !s.empty() && s.size() <= max &&
         std::all_of(s.begin(), s.end(), [](char ch) { return ch >= ' ' && ch < 0x7F; });
}

bool parse_switch(std::string_view text, bool& out) noexcept {
  if (text != "0" && text != "1") return false;
  out = text == "1";
  return true;
}

struct Placement {
  bool port_given = false;
};

// One arm's "key=value,..." onto c (model first: it picks the base config); "" or a message.
std::string parse_one(std::string_view entry, std::size_t index, SimJacoConfig& c, Placement& p) {
  const std::vector<std::string_view> items =
      entry.empty() || entry == "1" ? std::vector<std::string_view>{} : split(entry, ',');
  std::vector<std::pair<std::string_view, std::string_view>> pairs;
  for (const std::string_view item : items) {
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) return "'" + std::string(item) + "' is not key=value";
    pairs.emplace_back(trim(item.substr(0, eq)), trim(item.substr(eq + 1)));
  }
  c = SimJacoConfig{};
  for (const auto& [key, value] : pairs) {
    if (key != "model") continue;
    if (value == "v1") {
      c = simulation::sim_jaco_v1_config();
    } else if (value != "jaco2") {
      return "bad value '" + std::string(value) + "' for model (jaco2 or v1)";
    }
  }
  static constexpr char HEX[] = "0123456789ABCDEF";
  if (index > 0) {
    c.serial.back() = HEX[index % 16];
    c.client_name += "-" + std::to_string(index);
  }
  constexpr std::size_t STRING_MAX = drivers::jaco::CLIENT_STRING_BYTES - 1;
  for (const auto& [key, value] : pairs) {
    const std::string bad = "bad value '" + std::string(value) + "' for " + std::string(key);
    if (key == "model") {
      continue;
    } else if (key == "state") {
      if (value == "noinit") {
        c.start_state = ArmState::NOINIT;
      } else if (value == "normal") {
        c.start_state = ArmState::NORMAL;
      } else if (value == "ready") {
        c.start_state = ArmState::READY_STANDBY;
      } else if (value == "retract") {
        c.start_state = ArmState::RETRACT_STANDBY;
      } else {
        return bad + " (noinit, normal, ready or retract)";
      }
    } else if (key == "serial" || key == "name") {
      if (!printable(value, STRING_MAX)) return bad + " (1..19 printable characters)";
      (key == "serial" ? c.serial : c.client_name) = std::string(value);
    } else if (key == "usb_serial") {
      if (!printable(value, drivers::USB_SERIAL_MAX_BYTES))
        return bad + " (1..126 printable characters)";
      c.usb_serial = std::string(value);
    } else if (key == "bus") {
      unsigned bus = 0;
      if (!parse_number(value, bus) || bus < 1 || bus > 255) return bad + " (1..255)";
      c.bus = static_cast<std::uint8_t>(bus);
    } else if (key == "port") {
      unsigned port = 0;
      if (!parse_number(value, port) || port < 1 || port > 15) return bad + " (1..15)";
      c.port = static_cast<std::uint8_t>(port);
      p.port_given = true;
    } else if (key == "stale") {
      if (!parse_number(value, c.faults.stale_replies) ||
          c.faults.stale_replies > simulation::SIM_JACO_REPLY_QUEUE)
        return bad + " (0.." + std::to_string(simulation::SIM_JACO_REPLY_QUEUE) + ")";
    } else if (key == "drop_out") {
      if (!parse_rate(value, c.faults.drop_out_rate)) return bad + " (a rate in [0, 1])";
    } else if (key == "in_timeout") {
      if (!parse_rate(value, c.faults.in_timeout_rate)) return bad + " (a rate in [0, 1])";
    } else if (key == "garbage") {
      if (!parse_rate(value, c.faults.garbage_reply_rate)) return bad + " (a rate in [0, 1])";
    } else if (key == "corrupt") {
      if (!parse_rate(value, c.faults.corrupt_body_rate)) return bad + " (a rate in [0, 1])";
    } else if (key == "wrong_command") {
      if (!parse_rate(value, c.faults.wrong_command_rate)) return bad + " (a rate in [0, 1])";
    } else if (key == "fault_seed") {
      if (!parse_number(value, c.fault_seed)) return bad;
    } else if (key == "never_leave_noinit") {
      if (!parse_switch(value, c.faults.never_leave_noinit)) return bad + " (0 or 1)";
    } else if (key == "fw5_quirk") {
      if (!parse_switch(value, c.faults.fw5_ignore_first_joystick)) return bad + " (0 or 1)";
    } else {
      return "unknown key '" + std::string(key) + "'";
    }
  }
  return "";
}

// Gives every arm without port= the lowest free root port of its bus; refuses a taken one.
std::string place(Jacos& jacos, const std::vector<Placement>& placements,
                  const std::vector<simulation::SimKinectConfig>& kinects) {
  std::set<std::pair<unsigned, unsigned>> taken;  // (bus, root port)
  for (const simulation::SimKinectConfig& k : kinects) {
    if (!k.hub_ports.empty()) taken.insert({k.bus, k.hub_ports.front()});
  }
  for (std::size_t i = 0; i < jacos.size(); ++i) {
    if (!placements[i].port_given) continue;
    if (!taken.insert({jacos[i].bus, jacos[i].port}).second)
      return "JACO " + std::to_string(i) + ": port " + std::to_string(jacos[i].port) + " of bus " +
             std::to_string(jacos[i].bus) + " is already taken";
  }
  for (std::size_t i = 0; i < jacos.size(); ++i) {
    if (placements[i].port_given) continue;
    unsigned port = 1;
    while (port <= 15 && taken.count({jacos[i].bus, port}) != 0) ++port;
    if (port > 15) return "JACO " + std::to_string(i) + ": no free root port on its bus";
    jacos[i].port = static_cast<std::uint8_t>(port);
    taken.insert({jacos[i].bus, port});
  }
  return "";
}

}  // namespace

Result<Jacos, std::string> parse_jacos(std::string_view text,
                                       const std::vector<simulation::SimKinectConfig>& kinects) {
  try {
    Jacos jacos;
    text = trim(text);
    if (text.empty() || text == "0") return jacos;
    const std::vector<std::string_view> entries = split(text, ';');
    std::vector<Placement> placements(entries.size());
    for (std::size_t k = 0; k < entries.size(); ++k) {
      SimJacoConfig c;
      const std::string problem = parse_one(entries[k], k, c, placements[k]);
      if (!problem.empty()) return orthoflow::err("JACO " + std::to_string(k) + ": " + problem);
      jacos.push_back(std::move(c));
    }
    const std::string problem = place(jacos, placements, kinects);
    if (!problem.empty()) return orthoflow::err(problem);
    return jacos;
  } catch (const std::exception& e) {
    return orthoflow::err(std::string("cannot parse: ") + e.what());
  }
}

Result<Jacos, std::string> jacos_from_env(const std::vector<simulation::SimKinectConfig>& kinects) {
  const char* text = std::getenv(ENV_JACO);
  return parse_jacos(text == nullptr ? std::string_view{} : std::string_view(text), kinects);
}

}  // namespace orthoflow::sim_libusb
