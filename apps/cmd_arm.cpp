// `orthoflow arm list | info | state [--follow] | stop`: the Kinova JACO through orthoflow's driver
// (drivers/jaco/jaco_arm.hpp); --sim runs them on the simulated arm
// (simulation/devices/sim_jaco_transport.hpp), in real time. Motion (home, retract, move, fingers)
// is in cmd_arm_motion.cpp; what the sub-commands share (transport, starting the arm, options) is
// in arm_cli.cpp.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstring>
#include <iostream>
#include <sstream>
#include <thread>

#include "apps/arm_cli.hpp"
#include "engine/arm_state_payload.hpp"
#include "engine/ipc_pubsub.hpp"
#include "graphs/services/arm_state_feed.hpp"

namespace orthoflow::apps {

namespace {

using namespace arm_cli;
namespace jaco = drivers::jaco;

std::atomic<bool> follow_stop{false};
extern "C" void on_follow_stop(int) { follow_stop.store(true); }

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

}  // namespace

void add_arm_command(CLI::App& app) {
  auto* arm = app.add_subcommand("arm",
                                 "the Kinova JACO arm (list, info, state, home, retract, "
                                 "move, fingers, stop, reset, limits); --sim for the simulated "
                                 "arm");
  arm->require_subcommand(1);
  auto a = std::make_shared<ArmArgs>();
  auto* list = arm->add_subcommand("list", "list the JACO arms on USB");
  add_common_options(list, a);
  list->callback([a] { run_list(*a); });
  auto* info = arm->add_subcommand("info", "model, serial, firmware and state of the arm");
  add_common_options(info, a);
  info->callback([a] {
    a->what = "orthoflow arm info";
    run_info(*a);
  });
  auto* state = arm->add_subcommand("state", "joints, pose, fingers and state (--follow: 10 Hz)");
  add_common_options(state, a);
  state->add_flag("--follow", a->follow, "keep printing until Ctrl-C, SIGTERM or --seconds");
  state->add_option("--seconds", a->seconds, "with --follow: stop after this many seconds");
  state->add_flag("--publish", a->publish,
                  "with --follow: publish every 100 Hz snapshot on the iceoryx topic "
                  "orthoflow/jaco/state (needs a running RouDi)");
  state->callback([a] {
    a->what = "orthoflow arm state";
    run_state(*a);
  });
  add_motion_commands(arm, a);
  add_safety_commands(arm, a);
}

}  // namespace orthoflow::apps
