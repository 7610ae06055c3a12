// The arm's stop, timed on the wall clock (issue 49; docs/SAFETY.md): a threaded JacoArm paced to
// the wall clock on the simulated JACO (simulation/devices/sim_jaco_transport.hpp), moving, with
// stalls injected into its USB transfers (a random quarter of the OUT transfers wait 0 to 6 ms, the
// link's transfer deadline), stopped by each path in turn; each trial times, on steady_clock, the
// request to the first packet that commands zero velocity leaving the host (the trajectory FIFO
// erased). 1,000 trials a path; p50 / p99 / max in the counters. Not hardware: the real arm's own
// braking comes after this (docs/SAFETY.md).
//
// Paths: 0 estop() on the arm (what the web view's and the DDS bridge's requests end in, in the
// holder), 1 a signal (SIGTERM to the process: the guard thread turns it into the latched stop),
// 2 a stop request over iceoryx (graphs/services/arm_stop_service.hpp, the path of `orthoflow arm
// stop`, the stop button and the DDS stop topic; needs a running RouDi, else skipped with a
// message), 3 the watchdog (the client stops feeding it: the time counted from the last feed, so
// the 100 ms timeout is in it), 4 SIGINT and 5 SIGHUP (the same handler as SIGTERM).
// BM_MonitorCheck: the monitor's CPU per control cycle (check_cycle) on a velocity stream near a
// keep-out and on the firmware's HOME from RETRACT.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "drivers/jaco/jaco_arm.hpp"
#include "drivers/jaco/jaco_safety_monitor.hpp"
#include "engine/ipc_runtime.hpp"
#include "graphs/services/arm_stop_service.hpp"
#include "simulation/devices/forwarding_transport.hpp"
#include "simulation/devices/sim_jaco_transport.hpp"

namespace jaco = orthoflow::drivers::jaco;
namespace sim = orthoflow::simulation;

namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The simulated arm behind a decorator that stalls some OUT transfers and stamps every ERASE.
struct Owned {
  sim::SimJacoTransport arm;
};
class StallingTransport final : private Owned, public sim::ForwardingTransport {
 public:
  StallingTransport() : ForwardingTransport(Owned::arm) {
    sim::SimJacoConfig config;
    config.start_state = jaco::ArmState::READY_STANDBY;
    Owned::arm.add_arm(config);
  }
  std::atomic<std::int64_t> last_erase_ns{0};
  std::atomic<bool> stalls{true};

 protected:
  void on_call(const sim::SeamCall& call) const override {
    if (call.op != sim::SeamOp::INTERRUPT || call.number != jaco::EP_OUT || call.done ||
        call.data.size() != jaco::PACKET_BYTES)
      return;
    jaco::Packet p{};
    std::copy(call.data.begin(), call.data.end(), reinterpret_cast<std::byte*>(p.data()));
    if (jaco::read_header(p).command_id ==
        static_cast<std::uint16_t>(jaco::Command::ERASE_TRAJECTORIES))
      const_cast<StallingTransport*>(this)->last_erase_ns.store(steady_ns());
    if (stalls.load() && rng_() % 4 == 0)
      std::this_thread::sleep_for(std::chrono::microseconds(rng_() % 6000));
  }

 private:
  mutable std::minstd_rand rng_{7};
};

struct Arm {
  StallingTransport* usb = nullptr;
  std::unique_ptr<jaco::JacoArm> arm;
};

Arm start_arm() {
  auto usb = std::make_unique<StallingTransport>();
  Arm a;
  a.usb = usb.get();
  auto devices = jaco::list_arms(*usb);
  jaco::ArmOptions options;
  options.pace_to_wall_clock = true;
  auto started = jaco::JacoArm::start(std::move(usb), devices.value().front(), options);
  if (started) a.arm = std::move(started).value();
  return a;
}

// Sets the arm moving (a slow joint stream on the base joint, fed, ramped inside the acceleration
// cap so no submit is refused), for a random 20..60 ms.
void get_moving(Arm& a, std::minstd_rand& rng) {
  (void)a.arm->reset_estop();
  jaco::ArmCommand v;
  v.kind = jaco::ArmCommand::Kind::VELOCITY;
  const int cycles = 2 + static_cast<int>(rng() % 5);
  for (int i = 1; i <= cycles; ++i) {
    v.velocity = {0.1 * i, 0, 0, 0, 0, 0};  // 10 deg/s^2 a step: inside the 40 deg/s^2 cap
    (void)a.arm->submit(v);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

struct Latencies {
  std::vector<double> ms;
  void report(benchmark::State& state) {
    if (ms.empty()) return;
    std::sort(ms.begin(), ms.end());
    const auto at = [&](double p) {
      return ms[std::min(ms.size() - 1, static_cast<std::size_t>(p * double(ms.size())))];
    };
    state.counters["trials"] = static_cast<double>(ms.size());
    state.counters["p50_ms"] = at(0.5);
    state.counters["p99_ms"] = at(0.99);
    state.counters["max_ms"] = ms.back();
  }
};

// Waits up to 500 ms for an ERASE after @p since. @return its latency in ms, or -1.
double erase_after(const Arm& a, std::int64_t since) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
  while (std::chrono::steady_clock::now() < deadline) {
    const std::int64_t t = a.usb->last_erase_ns.load();
    if (t >= since) return 1e-6 * static_cast<double>(t - since);
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  return -1.0;
}

void BM_StopLatency(benchmark::State& state) {
  const int path = static_cast<int>(state.range(0));
  const char* names[] = {"estop() call", "SIGTERM", "iceoryx stop request",
                         "watchdog",     "SIGINT",  "SIGHUP"};
  state.SetLabel(names[path]);
  std::unique_ptr<orthoflow::graphs::ArmStopListener> listener;
  Arm a = start_arm();
  if (!a.arm) return state.SkipWithError("the simulated arm did not start");
  if (path == 1 || path >= 4) jaco::install_stop_signals();
  if (path == 2) {
    if (!orthoflow::engine::probe_roudi())
      return state.SkipWithError("no RouDi running: start `iox-roudi -c config/roudi_test.toml`");
    (void)orthoflow::engine::init_ipc_runtime("orthoflow_stop_bench");
    jaco::JacoArm* raw = a.arm.get();
    auto l = orthoflow::graphs::ArmStopListener::start(
        [raw](std::string_view why) { return raw->estop(why); }, "bench");
    if (!l) return state.SkipWithError(l.error().c_str());
    listener = std::move(*l);
  }
  std::minstd_rand rng(11);
  Latencies lat;
  int failures = 0;
  const int trials = 1000;
  for (auto _ : state) {
    for (int t = 0; t < trials; ++t) {
      get_moving(a, rng);
      std::int64_t since = steady_ns();
      switch (path) {
        case 0:
          (void)a.arm->estop("bench");
          break;
        case 1:
          std::raise(SIGTERM);
          break;
        case 2:
          (void)orthoflow::graphs::request_arm_stop("bench", std::chrono::milliseconds(500));
          break;
        case 4:
          std::raise(SIGINT);
          break;
        case 5:
          std::raise(SIGHUP);
          break;
        default:
          since = steady_ns();  // the last feed was the last submit, just now
          break;
      }
      const double ms = erase_after(a, since);
      if (ms < 0.0)
        ++failures;
      else
        lat.ms.push_back(ms);
    }
  }
  lat.report(state);
  state.counters["lost"] = failures;
  listener.reset();
}

// The monitor's CPU per check: a velocity stream 2 cm from a keep-out, and HOME's firmware cycles.
void BM_MonitorCheck(benchmark::State& state) {
  jaco::SafetyLimits limits;
  jaco::CycleIntent intent;
  intent.joints = jaco::HOME_JOINTS;
  if (state.range(0) == 0) {
    state.SetLabel("velocity stream near a keep-out");
    const Eigen::Vector3d hand = jaco::forward_kinematics(intent.joints).translation();
    jaco::Box b{hand + Eigen::Vector3d(0.12, -0.05, -0.05), hand + Eigen::Vector3d(0.2, 0.05, 0.05),
                orthoflow::core::FixedText<24>::from("box")};
    (void)limits.add_keep_out(b);
    intent.velocity = intent.previous = intent.command = {20.0, 0, 0, 0, 0, 0};
  } else {
    state.SetLabel("firmware HOME from RETRACT, table and base keep-outs");
    jaco::Box table{{-0.9, -0.9, -0.2}, {0.9, 0.9, 0.0}, orthoflow::core::FixedText<24>::from("t")};
    jaco::Box base{
        {-0.075, -0.075, -0.1}, {0.075, 0.075, 0.16}, orthoflow::core::FixedText<24>::from("b")};
    base.from = jaco::BodyPart::FOREARM;
    (void)limits.add_keep_out(table);
    (void)limits.add_keep_out(base);
    intent.joints = {270.0, 200.0, 35.0, 268.0, 88.0, 88.0};
    intent.firmware = true;
    intent.firmware_goal = jaco::HOME_JOINTS;
    intent.velocity = {0.0, -30.0, 20.0, -10.0, -5.0, -10.0};
  }
  jaco::MonitorCost cost;
  for (auto _ : state) {
    auto r = jaco::check_cycle(limits, intent, &cost);
    benchmark::DoNotOptimize(r);
  }
  state.counters["stretches"] = static_cast<double>(cost.nodes);
}

// The worst stopping distance of any point of the body at the speed cap: every joint at the cap in
// its worse direction, held for the command latency, then braked at the monitor's deceleration
// (the model docs/SAFETY.md states), over 2,000 seeded joint configurations; the largest
// displacement of any capsule end (links, hand, fingertips).
void BM_StoppingDistance(benchmark::State& state) {
  const jaco::SafetyLimits limits;
  const double v = limits.max_joint_speed_deg_s;
  const double turn = v * 1e-9 * double(limits.command_latency_ns) +
                      jaco::braking_distance_deg(v, limits.brake_decel_deg_s2);
  std::minstd_rand rng(3);
  std::uniform_real_distribution<double> offset(-60.0, 60.0);
  double worst = 0.0;
  for (auto _ : state) {
    for (int n = 0; n < 2000; ++n) {
      jaco::JointAngles q = jaco::HOME_JOINTS;
      for (double& a : q) a += offset(rng);
      q[1] = std::clamp(q[1], 60.0, 300.0);
      q[2] = std::clamp(q[2], 30.0, 330.0);
      jaco::BodyCapsules a{}, b{};
      const std::size_t na = jaco::body_capsules(q, *limits.geometry, limits.body, 1.0, {}, a);
      for (int signs = 0; signs < 64; ++signs) {
        jaco::JointAngles p = q;
        for (std::size_t j = 0; j < 6; ++j) p[j] += ((signs >> j) & 1) != 0 ? turn : -turn;
        (void)jaco::body_capsules(p, *limits.geometry, limits.body, 1.0, {}, b);
        for (std::size_t c = 0; c < na; ++c)
          worst = std::max({worst, (a[c].a - b[c].a).norm(), (a[c].b - b[c].b).norm()});
      }
    }
  }
  state.counters["joint_turn_deg"] = turn;
  state.counters["worst_m"] = worst;
}

}  // namespace

BENCHMARK(BM_StoppingDistance)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StopLatency)
    ->DenseRange(0, 5)
    ->ArgName("path")
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_MonitorCheck)->DenseRange(0, 1)->ArgName("case")->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
