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
// the 100 ms timeout is in it), 4 SIGINT and 5 SIGHUP (the same handler as SIGTERM), 6 the web
// view's STOP ARM: an authenticated HTTP POST /api/arm/stop to a UiServer on loopback, which sends
// the stop request over iceoryx (ui/ipc_task_link.hpp) to the holder's listener and answers once
// the holder confirmed (needs a running RouDi, as path 2), 7 a stop from DDS: an
// orthoflow_msgs/ArmStop written on rt/orthoflow/arm/stop by a plain Cyclone DDS writer in this
// process, taken by the bridge's loop (bridge/bridge_loop.hpp, pumped as `orthoflow bridge dds`
// pumps it) and sent to the holder over iceoryx (needs a RouDi; built with Cyclone DDS only).
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
#include "ui/ipc_task_link.hpp"
#ifdef ORTHOFLOW_BENCH_DDS
#include <dds/dds.h>

#include "bridge/bridge_loop.hpp"
#include "orthoflow_msgs/msg/ArmStop.h"
#endif
#include "ui/ui_client.hpp"
#include "ui/ui_server.hpp"

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

// The web view's server for path 6: no graph behind it (nothing to show), only the task link.
class StopOnlyBackend final : public orthoflow::ui::UiBackend {
 public:
  orthoflow::ui::UiSnapshot snapshot() const override { return {}; }
  orthoflow::ui::UiAnswer submit(const orthoflow::ui::UiAction& /*action*/,
                                 int /*timeout_ms*/) override {
    return {};
  }
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

#ifdef ORTHOFLOW_BENCH_DDS
// Path 7: the bridge's loop on its own thread, pumped as `orthoflow bridge dds` pumps it (again at
// once after work, else after 1 ms), and a plain DDS writer of ArmStop matched to it.
class DdsStopper {
 public:
  static constexpr std::uint32_t DOMAIN = 212;  // no test uses it
  ~DdsStopper() {
    stop_.store(true);
    if (pump_.joinable()) pump_.join();
    if (participant_ > 0) dds_delete(participant_);
  }
  /// @return "" once the writer matched the bridge's reader, else why not.
  std::string start() {
    orthoflow::bridge::BridgeConfig config;
    config.domain = DOMAIN;
    auto loop = orthoflow::bridge::BridgeLoop::open(config, 0x57095709ULL);
    if (!loop) return loop.error();
    loop_ = std::move(*loop);
    pump_ = std::thread([this] {
      while (!stop_.load())
        if (loop_->pump(steady_ns()) == 0)
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
    });
    participant_ = dds_create_participant(DOMAIN, nullptr, nullptr);  // the bridge's domain
    const dds_entity_t topic =
        dds_create_topic(participant_, &orthoflow_msgs_msg_dds__ArmStop__desc,
                         "rt/orthoflow/arm/stop", nullptr, nullptr);
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 16);
    writer_ = dds_create_writer(participant_, topic, q, nullptr);
    dds_delete_qos(q);
    if (participant_ < 0 || topic < 0 || writer_ < 0) return "cannot create the DDS writer";
    for (int i = 0; i < 2000; ++i) {
      dds_publication_matched_status_t matched;
      if (dds_get_publication_matched_status(writer_, &matched) == DDS_RETCODE_OK &&
          matched.current_count > 0)
        return "";
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return "the bridge's ArmStop reader did not match within 10 s";
  }
  bool send() {
    orthoflow_msgs_msg_dds__ArmStop_ stop;
    stop.reason = const_cast<char*>("stop bench");
    return dds_write(writer_, &stop) == DDS_RETCODE_OK;
  }

 private:
  std::unique_ptr<orthoflow::bridge::BridgeLoop> loop_;
  std::thread pump_;
  std::atomic<bool> stop_{false};
  dds_entity_t participant_ = 0, writer_ = 0;
};
#endif

void BM_StopLatency(benchmark::State& state) {
  const int path = static_cast<int>(state.range(0));
  const char* names[] = {
      "estop() call", "SIGTERM", "iceoryx stop request",        "watchdog",
      "SIGINT",       "SIGHUP",  "web view POST /api/arm/stop", "DDS ArmStop through the bridge"};
  state.SetLabel(names[path]);
  std::unique_ptr<orthoflow::graphs::ArmStopListener> listener;
  Arm a = start_arm();
  if (!a.arm) return state.SkipWithError("the simulated arm did not start");
  if (path == 1 || path >= 4) jaco::install_stop_signals();
  StopOnlyBackend backend;
  std::unique_ptr<orthoflow::ui::IpcTaskLink> link;
  std::unique_ptr<orthoflow::ui::UiServer> server;
  orthoflow::ui::ClientTarget web;
#ifdef ORTHOFLOW_BENCH_DDS
  std::unique_ptr<DdsStopper> dds;
#else
  if (path == 7) return state.SkipWithError("built without Cyclone DDS: no bridge");
#endif
  if (path == 2 || path >= 6) {
    if (!orthoflow::engine::probe_roudi())
      return state.SkipWithError("no RouDi running: start `iox-roudi -c config/roudi_test.toml`");
    (void)orthoflow::engine::init_ipc_runtime("orthoflow_stop_bench");
    jaco::JacoArm* raw = a.arm.get();
    auto l = orthoflow::graphs::ArmStopListener::start(
        [raw](std::string_view why) { return raw->estop(why); }, "bench");
    if (!l) return state.SkipWithError(l.error().c_str());
    listener = std::move(*l);
  }
#ifdef ORTHOFLOW_BENCH_DDS
  if (path == 7) {
    dds = std::make_unique<DdsStopper>();
    if (const std::string why = dds->start(); !why.empty()) return state.SkipWithError(why.c_str());
  }
#endif
  if (path == 6) {
    auto opened = orthoflow::ui::IpcTaskLink::open("tabletop");
    if (!opened) return state.SkipWithError(opened.error().c_str());
    link = std::move(*opened);
    backend.set_task_link(link.get());
    orthoflow::ui::UiServerConfig config;  // loopback, an ephemeral port
    config.token = orthoflow::ui::generate_token();
    config.rate = {1000.0, 1000.0, 64};  // this bench posts 1,000 stops in a row
    auto started = orthoflow::ui::UiServer::start(config, backend);
    if (!started) return state.SkipWithError(started.error().c_str());
    server = std::move(*started);
    web = {"127.0.0.1", server->port(), config.token, 5000};
  }
  std::minstd_rand rng(11);
  Latencies lat;
  int failures = 0, refused = 0;
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
#ifdef ORTHOFLOW_BENCH_DDS
        case 7:
          if (!dds->send()) ++refused;
          break;
#endif
        case 6:
          if (auto r = orthoflow::ui::send_ui_request(web, "POST", "/api/arm/stop", "{}");
              !r || r->status != 200)
            ++refused;
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
  if (path == 6) state.counters["http_not_200"] = refused;
  if (path == 7) state.counters["write_failed"] = refused;
#ifdef ORTHOFLOW_BENCH_DDS
  dds.reset();
#endif
  server.reset();
  link.reset();
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
    ->DenseRange(0, 7)
    ->ArgName("path")
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_MonitorCheck)->DenseRange(0, 1)->ArgName("case")->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
