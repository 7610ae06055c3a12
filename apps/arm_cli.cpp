// What the `orthoflow arm ...` sub-commands share (apps/arm_cli.hpp): the error exit, the
// transport (libusb, or the simulated JACO with --sim, in real time), finding and starting the arm
// with the limits of the options, the JSON of a snapshot and the common options. The sub-commands
// are in cmd_arm.cpp (list, info, state, stop) and cmd_arm_motion.cpp (home, retract, move,
// fingers).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

#include <unistd.h>

#include "apps/arm_cli.hpp"
#include "drivers/usb/libusb_transport.hpp"
#include "engine/ipc_runtime.hpp"
#include "manipulation/robot_frames.hpp"
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
  if (box_name.empty() || box_name.size() > 23)
    fail(what + ": a box's name has 1 to 23 characters", EXIT_USAGE);
  const auto v = parse_numbers(numbers, 6, what);
  jaco::Box box;
  box.min = {v[0], v[1], v[2]};
  box.max = {v[3], v[4], v[5]};
  // Corners in order only: a swapped pair is more likely a typo than a box (docs/SAFETY.md).
  if (!(box.min.array() < box.max.array()).all())
    fail(what + " " + text + ": an inverted or empty box (x0 < x1, y0 < y1, z0 < z1 are needed)",
         EXIT_USAGE);
  box.name.assign(box_name);
  return box;
}

}  // namespace

std::string state_dir_path(const ArmArgs& a) {
  return a.state_dir.empty() ? jaco::ArmStateDir::default_path(a.sim) : a.state_dir;
}

manipulation::ArmLimitsFile load_limits(const ArmArgs& a) {
  manipulation::ArmLimitsFile file = manipulation::default_arm_limits();
  const std::string path = !a.limits.empty()                          ? a.limits
                           : ::access(DEFAULT_LIMITS_PATH, F_OK) == 0 ? DEFAULT_LIMITS_PATH
                                                                      : "";
  if (!path.empty()) {
    auto loaded = manipulation::load_arm_limits(path);
    if (!loaded) fail(loaded.error(), EXIT_BAD_INPUT);
    file = std::move(*loaded);
  }
  jaco::SafetyLimits& limits = file.limits;
  if (!a.workspace.empty()) limits.workspace = parse_box(a.workspace, "--workspace", "workspace");
  for (const std::string& box : a.keep_out) {
    const jaco::Box b = parse_box(box, "--keep-out", "keep-out");
    if (limits.find_keep_out(b.name.view()) != nullptr)
      fail("--keep-out: a box named '" + std::string(b.name.view()) + "' exists already",
           EXIT_USAGE);
    if (!limits.add_keep_out(b))
      fail("at most " + std::to_string(jaco::MAX_KEEP_OUT) + " keep-out boxes", EXIT_USAGE);
  }
  std::optional<Eigen::Isometry3d> camera = a.base_from_camera;
  if (!camera && !a.frames.empty()) {
    const auto frames = manipulation::load_robot_frames(a.frames);
    if (!frames) fail(frames.error(), EXIT_BAD_INPUT);
    camera = frames->base_from_camera;
  }
  if (camera) {
    if (auto placed = manipulation::place_camera_keep_out(file, *camera); !placed)
      fail(placed.error(), EXIT_USAGE);
  }
  return file;
}

HeldArm start_arm(const ArmArgs& a, std::vector<jaco::StateCallback> subscribers) {
  const manipulation::ArmLimitsFile limits = load_limits(a);
  auto transport = make_transport(a);
  const auto device = find_arm(*transport, a);
  jaco::ArmOptions options;
  options.subscribers = std::move(subscribers);
  options.pace_to_wall_clock = a.sim;  // the simulated arm moves as fast as a real one
  options.controller.limits = limits.limits;
  options.state_dir = state_dir_path(a);
  options.holder = a.what;
  // Before the arm is open: a signal from here on halts it in place and latches it.
  if (a.motion) jaco::install_stop_signals();
  std::string busy;
  auto arm = jaco::JacoArm::start(std::move(transport), device, std::move(options), &busy);
  if (!arm.has_value()) {
    if (!busy.empty()) fail("the arm is not free: " + busy);
    fail("cannot open the arm: " + jaco::to_string(arm.error()));
  }
  HeldArm held;
  held.arm = std::move(arm).value();
  if (a.motion && !limits.camera_removed && limits.limits.find_keep_out("camera") == nullptr)
    std::cerr << "orthoflow arm: warning: no camera keep-out: give --frames ROBOT_FRAMES to place "
                 "it, or say `remove: [camera]` in the limits file (docs/SAFETY.md)\n";
  if (a.motion && !held->realtime_guard())
    std::cerr << "orthoflow arm: note: the guard thread runs without SCHED_FIFO (it needs "
                 "CAP_SYS_NICE or an rtprio limit, docs/SAFETY.md); it still runs every 2 ms\n";
  if (a.motion) {
    if (const std::string latched = held->latch_reason(); !latched.empty())
      fail("the arm's stop is latched (" + latched + ") in " + state_dir_path(a) +
           ": check the arm, then `orthoflow arm reset`");
  }
  // Reachable by `orthoflow arm stop`, the web view and the DDS bridge whenever RouDi runs.
  if (engine::ipc_runtime_ready() || engine::probe_roudi()) {
    const bool ready = engine::ipc_runtime_ready() ||
                       engine::init_ipc_runtime("orthoflow_arm_" + std::to_string(::getpid()));
    if (ready) {
      jaco::JacoArm* raw = held.arm.get();
      auto listener = graphs::ArmStopListener::start(
          [raw](std::string_view reason) { return raw->estop(reason); }, a.what);
      if (listener)
        held.stop_listener = std::move(*listener);
      else
        std::cerr << "orthoflow arm: no stop over iceoryx: " << listener.error() << '\n';
    }
  }
  return held;
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
  sub->add_option("--limits", a->limits,
                  std::string("the arm's limits file (docs/SAFETY.md; default ") +
                      DEFAULT_LIMITS_PATH + " if present, else the built-in limits)");
  sub->add_option("--state-dir", a->state_dir,
                  "the arm's state directory: holder lock and latched stop (default "
                  "$ORTHOFLOW_ARM_STATE_DIR, else /var/lib/orthoflow/arm; --sim: "
                  "/tmp/orthoflow-sim-arm-UID)");
}

}  // namespace orthoflow::apps::arm_cli
