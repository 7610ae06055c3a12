// What the `orthoflow arm ...` sub-commands share (apps/arm_cli.hpp): the error exit, the
// transport (libusb, or the simulated JACO with --sim, in real time), finding and starting the arm
// with the limits of the options, the JSON of a snapshot and the common options. The sub-commands
// are in cmd_arm.cpp (list, info, state, stop) and cmd_arm_motion.cpp (home, retract, move,
// fingers).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

#include "apps/arm_cli.hpp"
#include "drivers/usb/libusb_transport.hpp"
#include "simulation/devices/sim_jaco_transport.hpp"

namespace orthoflow::apps::arm_cli {

namespace jaco = drivers::jaco;

[[noreturn]] void fail(const std::string& what, int code) {
  std::cerr << "orthoflow arm: " << what << '\n';
  throw CLI::RuntimeError(code);
}

std::unique_ptr<drivers::UsbTransport> make_transport(const ArmArgs& a) {
  if (a.sim) {
    auto sim = std::make_unique<simulation::SimJacoTransport>();
    simulation::SimJacoConfig config =
        a.sim_model == "v1" ? simulation::sim_jaco_v1_config() : simulation::SimJacoConfig{};
    config.start_state = a.sim_start == "noinit"    ? jaco::ArmState::NOINIT
                         : a.sim_start == "retract" ? jaco::ArmState::RETRACT_STANDBY
                         : a.sim_start == "normal"  ? jaco::ArmState::NORMAL
                                                    : jaco::ArmState::READY_STANDBY;
    config.faults.never_leave_noinit = a.sim_never_init;
    sim->add_arm(std::move(config));
    return sim;
  }
  auto usb = drivers::LibusbTransport::create();
  if (!usb.has_value()) fail("cannot start libusb: " + drivers::to_string(usb.error()));
  return std::move(usb.value());
}

drivers::UsbDeviceInfo find_arm(drivers::UsbTransport& t, const ArmArgs& a) {
  auto arms = jaco::list_arms(t);
  if (!arms.has_value()) fail(jaco::to_string(arms.error()));
  if (arms.value().empty()) fail("no Kinova JACO found (vendor 22cd; see docs/JACO.md for udev)");
  if (a.serial.empty()) return arms.value().front();
  for (const auto& arm : arms.value()) {
    if (arm.serial.view() == a.serial) return arm;
  }
  fail("no JACO with USB serial " + a.serial);
}

std::vector<double> parse_numbers(const std::string& text, std::size_t count,
                                  const std::string& what) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v))
      fail(what + ": '" + item + "' is not a finite number", EXIT_USAGE);
    values.push_back(v);
  }
  if (values.size() != count)
    fail(what + " needs " + std::to_string(count) + " comma-separated numbers, got " +
             std::to_string(values.size()),
         EXIT_USAGE);
  return values;
}

namespace {

jaco::Box parse_box(const std::string& text, const std::string& what, const std::string& name) {
  std::string numbers = text;
  std::string box_name = name;
  // An optional seventh field names the box: x0,y0,z0,x1,y1,z1,table
  std::size_t commas = 0;
  for (char c : text) commas += c == ',' ? 1U : 0U;
  if (commas == 6) {
    const auto last = text.rfind(',');
    numbers = text.substr(0, last);
    box_name = text.substr(last + 1);
  }
  const auto v = parse_numbers(numbers, 6, what);
  jaco::Box box;
  box.min = {std::min(v[0], v[3]), std::min(v[1], v[4]), std::min(v[2], v[5])};
  box.max = {std::max(v[0], v[3]), std::max(v[1], v[4]), std::max(v[2], v[5])};
  box.name.assign(box_name);
  return box;
}

}  // namespace

std::unique_ptr<jaco::JacoArm> start_arm(const ArmArgs& a,
                                         std::vector<jaco::StateCallback> subscribers) {
  auto transport = make_transport(a);
  const auto device = find_arm(*transport, a);
  jaco::ArmOptions options;
  options.subscribers = std::move(subscribers);
  options.pace_to_wall_clock = a.sim;  // the simulated arm moves as fast as a real one
  if (!a.workspace.empty())
    options.controller.limits.workspace = parse_box(a.workspace, "--workspace", "workspace");
  for (const std::string& box : a.keep_out) {
    if (!options.controller.limits.add_keep_out(parse_box(box, "--keep-out", "keep-out")))
      fail("at most " + std::to_string(jaco::MAX_KEEP_OUT) + " keep-out boxes", EXIT_USAGE);
  }
  auto arm = jaco::JacoArm::start(std::move(transport), device, std::move(options));
  if (!arm.has_value()) fail("cannot open the arm: " + jaco::to_string(arm.error()));
  return std::move(arm).value();
}

nlohmann::json snapshot_json(const jaco::ArmSnapshot& s) {
  nlohmann::json out = {
      {"stamp_ns", s.stamp_ns},
      {"cycle", s.cycle},
      {"joints_deg", s.joints},
      {"joint_velocity_deg_s", s.velocity},
      {"fingers", s.fingers},
      {"position_m", {s.pose.position.x(), s.pose.position.y(), s.pose.position.z()}},
      {"theta_rad", {s.pose.theta.x(), s.pose.theta.y(), s.pose.theta.z()}},
      {"currents_a", s.currents},
      {"voltage_v", s.sensors.voltage_v},
      {"actuator_temp_c", s.sensors.actuator_temp_c},
      {"arm_state", jaco::to_string(s.arm_state)},
      {"control", jaco::to_string(s.control)},
      {"last_stop", jaco::to_string(s.last_stop)},
      {"estop", s.estop},
      {"fault", s.fault},
      {"watchdog_stops", s.watchdog_stops},
      {"refused", s.refused},
      {"points_sent", s.points_sent},
      {"cycles_overrun", s.cycles_overrun}};
  if (s.fault) out["fault_error"] = jaco::to_string(s.fault_error);
  return out;
}

void add_common_options(CLI::App* sub, const std::shared_ptr<ArmArgs>& a) {
  sub->add_flag("--sim", a->sim, "use the simulated JACO (no USB needed; runs in real time)");
  sub->add_option("--sim-start", a->sim_start, "simulated arm's power-up state")
      ->check(CLI::IsMember({"noinit", "home", "retract", "normal"}));
  sub->add_option("--sim-model", a->sim_model, "simulated model: jaco2 (DSP 5) or v1 (DSP 4)")
      ->check(CLI::IsMember({"jaco2", "v1"}));
  sub->add_flag("--sim-never-init", a->sim_never_init,
                "fault: the simulated arm never leaves NOINIT");
  sub->add_option("--serial", a->serial, "the arm's USB serial (default: the first JACO)");
  sub->add_flag("--json", a->json, "JSON output");
}

}  // namespace orthoflow::apps::arm_cli
