// `orthoflow arm list | info | state [--follow] | stop`: the Kinova JACO through orthoflow's driver
// (drivers/jaco_arm.hpp); --sim runs them on the simulated arm (simulation/sim_jaco_transport.hpp),
// in real time. Motion (home, retract, move, fingers) is in cmd_arm_motion.cpp.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <iostream>
#include <sstream>
#include <thread>

#include "apps/arm_cli.hpp"
#include "drivers/libusb_transport.hpp"
#include "engine/arm_state_payload.hpp"
#include "engine/ipc_pubsub.hpp"
#include "graphs/arm_state_feed.hpp"
#include "simulation/sim_jaco_transport.hpp"

namespace orthoflow::apps {
namespace arm_cli {

namespace jaco = drivers::jaco;

namespace {
std::atomic<bool> follow_stop{false};
extern "C" void on_follow_stop(int) { follow_stop.store(true); }
}  // namespace

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

}  // namespace arm_cli

namespace {

using namespace arm_cli;

constexpr std::string_view ARM_STATE_TOPIC = engine::ARM_STATE_TOPIC;

void run_list(const ArmArgs& a) {
  auto transport = make_transport(a);
  auto arms = jaco::list_arms(*transport);
  if (!arms.has_value()) fail(jaco::to_string(arms.error()));
  nlohmann::json out = nlohmann::json::array();
  for (const auto& d : arms.value()) {
    out.push_back(
        {{"bus", d.bus}, {"address", d.address}, {"serial", std::string(d.serial.view())}});
  }
  if (a.json) {
    std::cout << out.dump(2) << '\n';
    return;
  }
  if (out.empty()) std::cout << "no Kinova JACO found\n";
  for (const auto& d : out) {
    std::cout << "jaco  bus " << d["bus"] << " address " << d["address"] << "  serial "
              << d["serial"].get<std::string>() << '\n';
  }
}

std::string version(const jaco::FirmwareVersion& v) {
  return std::to_string(v.major) + "." + std::to_string(v.minor) + "." + std::to_string(v.patch);
}

void run_info(const ArmArgs& a) {
  auto arm = start_arm(a);
  const auto& id = arm->identity();
  const auto s = arm->snapshot();
  nlohmann::json out = {{"model", jaco::to_string(id.model)},
                        {"model_string", std::string(id.client.model.view())},
                        {"serial", std::string(id.client.serial.view())},
                        {"name", std::string(id.client.name.view())},
                        {"organisation", std::string(id.client.organisation.view())},
                        {"dsp_firmware", version(id.firmware.dsp)},
                        {"arm_state", jaco::to_string(s.arm_state)},
                        {"joints_deg", s.joints}};
  if (a.json) {
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << "JACO " << out["model"].get<std::string>() << " (\""
            << out["model_string"].get<std::string>() << "\")  serial "
            << out["serial"].get<std::string>() << "  name " << out["name"].get<std::string>()
            << "\nDSP firmware " << out["dsp_firmware"].get<std::string>() << "  state "
            << out["arm_state"].get<std::string>() << '\n';
}

void print_snapshot(const jaco::ArmSnapshot& s, bool json) {
  if (json) {
    std::cout << snapshot_json(s).dump() << '\n';
    return;
  }
  std::ostringstream line;
  line.setf(std::ios::fixed);
  line.precision(2);
  line << "joints";
  for (double q : s.joints) line << ' ' << q;
  line.precision(3);
  line << " deg  xyz " << s.pose.position.x() << ' ' << s.pose.position.y() << ' '
       << s.pose.position.z() << " m  fingers " << s.fingers[0] << ' ' << s.fingers[1] << ' '
       << s.fingers[2] << "  " << jaco::to_string(s.arm_state) << ' ' << jaco::to_string(s.control)
       << (s.fault ? "  FAULT: " + jaco::to_string(s.fault_error) : "");
  std::cout << line.str() << '\n';
}

/// The iceoryx side of `state --follow --publish`: topic orthoflow/jaco/state, one ArmStatePayload
/// per control cycle, loaned and filled on the arm's USB thread (no allocation there).
struct StatePublisher {
  std::unique_ptr<engine::IpcPublisher> publisher;
  std::atomic<bool> roudi_alive{true};
  std::atomic<std::uint64_t> published{0};
  /// The simulated arm's clock starts at 0: its states are stamped on the host's steady clock
  /// when they are published (within one 10 ms cycle of the read; the simulation is paced to the
  /// wall clock), the clock a real arm's transport and every frame stamp use.
  bool host_stamps = false;

  void publish(const jaco::ArmSnapshot& s) noexcept {
    if (!roudi_alive.load(std::memory_order_acquire)) {
      publisher->count_unpublished();
      return;
    }
    auto chunk = publisher->loan(sizeof(engine::ArmStatePayload));
    if (!chunk) return;  // counted by the publisher (loan_failures)
    const engine::ArmStatePayload p = graphs::arm_state_payload(
        s, host_stamps ? std::chrono::duration_cast<std::chrono::nanoseconds>(
                             std::chrono::steady_clock::now().time_since_epoch())
                             .count()
                       : s.stamp_ns);
    std::memcpy(chunk.value().data(), &p, sizeof p);
    if (publisher->publish(chunk.value())) published.fetch_add(1, std::memory_order_relaxed);
  }
};

std::unique_ptr<StatePublisher> make_state_publisher() {
  if (auto init = engine::init_ipc_runtime("orthoflow_arm_" + std::to_string(::getpid())); !init)
    fail(to_string(init.error()), EXIT_NO_ROUDI);
  auto pools = engine::query_roudi_pools(std::chrono::milliseconds(3000));
  if (!pools) fail(to_string(pools.error()), EXIT_NO_ROUDI);
  auto topic = engine::parse_topic(std::string(ARM_STATE_TOPIC));
  engine::IpcPublisherConfig config{{engine::ARM_STATE_TYPE_ID, engine::ARM_STATE_VERSION},
                                    sizeof(engine::ArmStatePayload),
                                    1,
                                    false};
  auto publisher = engine::IpcPublisher::create(topic.value(), config, pools.value());
  if (!publisher)
    fail(to_string(publisher.error()),
         publisher.error().code == engine::IpcError::Code::NO_FITTING_POOL ? EXIT_POOLS
                                                                           : EXIT_FAILURE_GENERIC);
  auto out = std::make_unique<StatePublisher>();
  out->publisher = std::move(publisher).value();
  return out;
}

void run_state(const ArmArgs& a) {
  if (a.publish && !a.follow) fail("--publish needs --follow", EXIT_USAGE);
  std::unique_ptr<StatePublisher> ipc;
  std::vector<jaco::StateCallback> subscribers;
  if (a.publish) {
    ipc = make_state_publisher();
    ipc->host_stamps = a.sim;
    subscribers.push_back([p = ipc.get()](const jaco::ArmSnapshot& s) { p->publish(s); });
  }
  auto arm = start_arm(a, std::move(subscribers));
  if (!a.follow) {
    print_snapshot(arm->snapshot(), a.json);
    return;
  }
  // 10 lines per second of the 100 Hz stream, until --seconds, Ctrl-C or SIGTERM: a signal ends the
  // loop like the time limit does (the arm is closed and the count printed), exit 0.
  follow_stop.store(false);
  const auto previous_int = std::signal(SIGINT, on_follow_stop);
  const auto previous_term = std::signal(SIGTERM, on_follow_stop);
  const auto start = std::chrono::steady_clock::now();
  std::uint64_t printed_cycle = 0;
  while (!follow_stop.load() &&
         (a.seconds <= 0.0 ||
          std::chrono::steady_clock::now() - start < std::chrono::duration<double>(a.seconds))) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (ipc && !engine::probe_roudi()) {
      ipc->roudi_alive.store(false, std::memory_order_release);
      arm.reset();  // stop the arm's thread (and with it the publishing) before leaving
      fail("RouDi lost while publishing " + std::string(ARM_STATE_TOPIC), EXIT_ROUDI_LOST);
    }
    const auto s = arm->snapshot();
    if (s.cycle == printed_cycle) continue;
    printed_cycle = s.cycle;
    print_snapshot(s, a.json);
    if (s.fault) fail("the arm faulted: " + jaco::to_string(s.fault_error));
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  arm.reset();
  if (ipc) {
    std::cerr << "published " << ipc->published.load() << " states on " << ARM_STATE_TOPIC << '\n';
  }
}

void run_stop(const ArmArgs& a) {
  // Opening the arm releases the joystick and erases the trajectory FIFO (JacoController::open);
  // closing it hands control back to the joystick: whatever an earlier process left running stops.
  auto arm = start_arm(a);
  const auto s = arm->snapshot();
  arm.reset();
  if (a.json) {
    std::cout
        << nlohmann::json{{"stopped", true}, {"arm_state", jaco::to_string(s.arm_state)}}.dump()
        << '\n';
    return;
  }
  std::cout << "arm stopped (joystick released, trajectories erased)\n";
}

}  // namespace

void add_arm_command(CLI::App& app) {
  auto* arm = app.add_subcommand("arm",
                                 "the Kinova JACO arm (list, info, state, home, retract, "
                                 "move, fingers, stop); --sim for the simulated arm");
  arm->require_subcommand(1);
  auto a = std::make_shared<ArmArgs>();
  auto* list = arm->add_subcommand("list", "list the JACO arms on USB");
  add_common_options(list, a);
  list->callback([a] { run_list(*a); });
  auto* info = arm->add_subcommand("info", "model, serial, firmware and state of the arm");
  add_common_options(info, a);
  info->callback([a] { run_info(*a); });
  auto* state = arm->add_subcommand("state", "joints, pose, fingers and state (--follow: 10 Hz)");
  add_common_options(state, a);
  state->add_flag("--follow", a->follow, "keep printing until Ctrl-C, SIGTERM or --seconds");
  state->add_option("--seconds", a->seconds, "with --follow: stop after this many seconds");
  state->add_flag("--publish", a->publish,
                  "with --follow: publish every 100 Hz snapshot on the iceoryx topic "
                  "orthoflow/jaco/state (needs a running RouDi)");
  state->callback([a] { run_state(*a); });
  auto* stop = arm->add_subcommand("stop", "stop any motion: release the joystick, erase the FIFO");
  add_common_options(stop, a);
  stop->callback([a] { run_stop(*a); });
  add_motion_commands(arm, a);
}

}  // namespace orthoflow::apps
