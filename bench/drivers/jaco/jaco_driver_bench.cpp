// The JACO driver's cost and timing on the simulated arm
// (simulation/devices/sim_jaco_transport.hpp, simulated clock: every interrupt transfer takes 1 ms
// of simulated time). Not hardware.
//
// 1. BM_JacoCycle: host CPU per JacoController::cycle() while streaming joint moves (goal A and
//    back home at full speed, the next move submitted once a cycle sent no point), the simulator's
//    wait to the next 10 ms boundary included as JacoArm's thread does it (cycle_us). Every 250
//    cycles (timer paused) the same cycles run again, each part alone, on the packets of a run
//    captured once with the same schedule: the driver on canned replies with no simulator under it
//    (driver_us: the arm's recorded replies handed back in order, 1 ms per transfer on a
//    ManualClock), the packets through a bare SimJacoTransport (sim_us: transport + arm model) and
//    into a bare SimJacoArm (sim_arm_us: receive, step, take the reply). cycle_us - sim_us is the
//    second estimate of the driver's own cost; its share of one core at 100 Hz = driver_us / 10 ms.
//    Same packets, checked: the canned transport compares every OUT packet and its time with the
//    trace, and the three arms are compared after every block. BM_ReplayCycle: each part alone.
// 2. BM_CommandToUsbLatency: simulated time from submit(MOVE_JOINTS) to the first
//    SEND_BASIC_TRAJECTORY leaving on the wire (the OUT transfer's start; it reaches the arm 1 ms
//    later), over every 1 ms submit phase between one cycle's end and the next cycle's start, after
//    0..9 idle cycles (every slow-read slot). Deterministic. BM_Submit: CPU of submit() itself:
//    MOVE_JOINTS (the swept path check), MOVE_POSE near (IK from the seed, then the path) and
//    far (a base turn of 120 degrees: the IK's 12 restarts run).
// 3. BM_StateStreamJitter: the threaded JacoArm with pace_to_wall_clock on a SimJacoTransport for
//    2 s of wall time, streaming moves, a subscriber stamping every snapshot with steady_clock:
//    mean period and p50 / p99 / max |period - 10 ms|. Wall clock, one iteration.
// 4. BM_ForwardKinematics, BM_FkToPose, BM_InverseKinematics (near, far, unreachable),
//    BM_CheckJointMove (the swept path check submit() runs).
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "drivers/jaco/jaco_arm.hpp"
#include "drivers/jaco/jaco_controller.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_safety.hpp"
#include "simulation/devices/sim_jaco_arm.hpp"
#include "simulation/devices/sim_jaco_transport.hpp"
#include "tests/drivers/jaco/jaco_test_rig.hpp"

namespace jaco = orthoflow::drivers::jaco;
namespace sim = orthoflow::simulation;
using orthoflow::test::JacoRig;
using orthoflow::test::SentPacket;

namespace {

constexpr std::int64_t PERIOD_NS = jaco::ARM_PERIOD_NS;
constexpr double PERIOD_US = static_cast<double>(PERIOD_NS) * 1e-3;
constexpr std::size_t TRACE_CYCLES = 3000;  // 30 s of simulated time, about 15 moves
constexpr std::size_t BLOCK = 250;          // driver cycles between two replays
constexpr orthoflow::drivers::UsbTimeout TRANSFER_TIMEOUT{100};

std::int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

jaco::JointAngles offset(jaco::JointAngles q, const std::array<double, 6>& d) {
  for (std::size_t j = 0; j < 6; ++j) q[j] += d[j];
  return q;
}

jaco::JointAngles home() { return sim::SimJacoConfig{}.home_joints; }
jaco::JointAngles goal_a() { return offset(home(), {20.0, -10.0, 8.0, 30.0, -15.0, 40.0}); }

jaco::ArmCommand move_to(const jaco::JointAngles& q) {
  jaco::ArmCommand c;
  c.kind = jaco::ArmCommand::Kind::MOVE_JOINTS;
  c.joints = q;
  c.speed_fraction = 1.0;
  return c;
}

jaco::ArmCommand move_pose(const jaco::JointAngles& q) {
  jaco::ArmCommand c;
  c.kind = jaco::ArmCommand::Kind::MOVE_POSE;
  c.pose = jaco::to_pose(jaco::forward_kinematics(q));
  return c;
}

/// The move schedule of every rig here, so a capture and a timed run send the same packets: goal
/// A, home, goal A, ... at full speed; the next move is submitted after the first cycle that sent
/// the arm no trajectory point (the controller is idle again).
class Schedule {
 public:
  jaco::ArmCommand next() { return move_to(k_++ % 2 == 0 ? goal_a() : home()); }
  bool went_idle(const sim::SimJacoArm& arm) {
    const auto& c = arm.counters();
    const std::uint64_t points = c.points_queued + c.points_dropped + c.malformed_commands;
    const bool idle = points == points_;
    points_ = points;
    return idle;
  }

 private:
  int k_ = 0;
  std::uint64_t points_ = 0;
};

/// A controller straight on the simulator (no recording decorator): what is timed.
struct DirectRig {
  DirectRig() {
    sim.add_arm(JacoRig::home_config());
    auto devices = jaco::list_arms(sim);
    if (!devices || devices.value().empty()) return;
    auto opened = jaco::JacoController::open(sim, devices.value().front());
    if (!opened) return;
    controller = std::move(opened).value();
    next_ns = sim.clock().now_ns();
  }
  [[nodiscard]] bool ok() const { return controller != nullptr; }
  [[nodiscard]] sim::SimJacoArm& arm() { return sim.arm(0); }
  /// One period as JacoArm's thread runs it: feed the watchdog (the client), cycle, wait.
  void cycle() {
    controller->keep_alive();
    controller->cycle();
    next_ns += PERIOD_NS;
    const std::int64_t now = sim.clock().now_ns();
    if (now < next_ns) sim.run_for(std::chrono::nanoseconds(next_ns - now));
    next_ns = std::max(next_ns, sim.clock().now_ns());
  }
  bool submit(const jaco::ArmCommand& c) { return controller->submit(c).has_value(); }

  sim::SimJacoTransport sim;
  std::unique_ptr<jaco::JacoController> controller;
  std::int64_t next_ns = 0;
};

/// Every OUT packet of a recorded run: the start-up's, then TRACE_CYCLES cycles of the schedule.
struct Trace {
  std::vector<SentPacket> packets;
  std::size_t startup = 0;             // packets before the first cycle
  std::vector<std::size_t> cycle_end;  // packets [begin(c), cycle_end[c]) belong to cycle c
  std::vector<std::int64_t> boundary;  // the simulated time cycle c waits for
  std::vector<bool> submit_after;      // the schedule submitted its next move after cycle c
  std::vector<jaco::Packet> replies;   // the arm's reply to each packet (filled by a replay)
  [[nodiscard]] std::size_t cycles() const { return cycle_end.size(); }
  [[nodiscard]] std::size_t begin(std::size_t c) const {
    return c == 0 ? startup : cycle_end[c - 1];
  }
};

Trace capture_trace() {
  Trace trace;
  try {
    JacoRig rig;
    trace.startup = rig.recorder.sent.size();
    Schedule schedule;
    if (!rig.controller->submit(schedule.next())) return {};
    for (std::size_t c = 0; c < TRACE_CYCLES; ++c) {
      rig.cycle(true);
      trace.cycle_end.push_back(rig.recorder.sent.size());
      trace.boundary.push_back(rig.next_ns);
      const bool idle = schedule.went_idle(rig.arm());
      trace.submit_after.push_back(idle);
      if (idle && !rig.controller->submit(schedule.next())) return {};
    }
    trace.packets = rig.recorder.sent;
  } catch (const std::exception&) { return {}; }
  return trace;
}

bool record_replies(Trace& trace);

const Trace& captured_trace() {
  static const Trace trace = [] {
    Trace t = capture_trace();
    if (t.cycles() == 0 || !record_replies(t)) return Trace{};
    return t;
  }();
  return trace;
}

/// The simulator alone: the trace's transfers through a bare SimJacoTransport (OUT, then its IN),
/// and the same wait to each cycle's boundary.
class TransportReplay {
 public:
  bool reset(const Trace& trace) {
    handle_ = {};
    sim_ = std::make_unique<sim::SimJacoTransport>();
    sim_->add_arm(JacoRig::home_config());
    auto devices = sim_->enumerate(jaco::VENDOR_KINOVA, jaco::PID_JACO);
    if (!devices || devices.value().empty()) return false;
    auto handle = sim_->open(devices.value().front());
    if (!handle) return false;
    handle_ = std::move(handle).value();
    if (!sim_->claim_interface(handle_, jaco::INTERFACE)) return false;
    trace_ = &trace;
    ok_ = true;
    for (std::size_t i = 0; i < trace.startup; ++i) {
      advance_to(trace.packets[i].t_ns);  // the flush at open waited here
      exchange(trace.packets[i]);
    }
    return ok_;
  }
  void run(std::size_t first_cycle, std::size_t end_cycle) {
    for (std::size_t c = first_cycle; c < end_cycle; ++c) {
      for (std::size_t i = trace_->begin(c); i < trace_->cycle_end[c]; ++i) {
        exchange(trace_->packets[i]);
      }
      advance_to(trace_->boundary[c]);
    }
  }
  [[nodiscard]] bool ok() const { return ok_; }
  [[nodiscard]] const sim::SimJacoArm& arm() const { return sim_->arm(0); }

 private:
  void advance_to(std::int64_t t_ns) {
    const std::int64_t now = sim_->clock().now_ns();
    if (now < t_ns) sim_->run_for(std::chrono::nanoseconds(t_ns - now));
  }
  void exchange(const SentPacket& p) {
    out_ = p.bytes;
    const auto sent = sim_->interrupt(handle_, jaco::EP_OUT, out_, TRANSFER_TIMEOUT);
    const auto got = sim_->interrupt(handle_, jaco::EP_IN, in_, TRANSFER_TIMEOUT);
    ok_ = ok_ && sent.has_value() && got.has_value();
    benchmark::DoNotOptimize(in_);
    if (record_ != nullptr) record_->push_back(in_);
  }

 public:
  std::vector<jaco::Packet>* record_ = nullptr;  // capture only: keeps every reply

 private:
  std::unique_ptr<sim::SimJacoTransport> sim_;
  orthoflow::drivers::UsbDeviceHandle handle_;  // destroyed before sim_
  const Trace* trace_ = nullptr;
  jaco::Packet out_{};
  jaco::Packet in_{};
  bool ok_ = false;
};

/// The arm's replies to the trace's packets, for the canned-reply transport.
bool record_replies(Trace& trace) {
  TransportReplay replay;
  replay.record_ = &trace.replies;
  if (!replay.reset(trace)) return false;
  replay.run(0, trace.cycles());
  return replay.ok() && trace.replies.size() == trace.packets.size();
}

/// No simulator at all: a UsbTransport that hands the driver the trace's replies in order (each
/// transfer 1 ms on its own ManualClock, as on the simulator) and checks that every OUT packet
/// and its time are the trace's. Only what JacoController uses is implemented.
class CannedTransport final : public orthoflow::drivers::UsbTransport {
  using UsbError = orthoflow::drivers::UsbError;
  template <class T>
  using R = orthoflow::Result<T, UsbError>;
  static orthoflow::Unexpected<UsbError> fail(UsbError::Code code) {
    return orthoflow::err(UsbError{code, 0, "canned"});
  }

 public:
  explicit CannedTransport(const Trace& trace) : trace_(trace) {}
  [[nodiscard]] bool diverged() const { return diverged_; }
  void advance_to(std::int64_t t_ns) {
    if (t_ns > clock_.now_ns()) clock_.set_ns(t_ns);
  }

  R<std::vector<orthoflow::drivers::UsbDeviceInfo>> enumerate(
      std::uint16_t, std::optional<std::uint16_t>) override {
    orthoflow::drivers::UsbDeviceInfo d;
    d.bus = 1;
    d.address = 2;
    d.vendor = jaco::VENDOR_KINOVA;
    d.product = jaco::PID_JACO;
    d.interface_count = 1;
    return std::vector<orthoflow::drivers::UsbDeviceInfo>{d};
  }
  R<orthoflow::drivers::UsbDeviceHandle> open(const orthoflow::drivers::UsbDeviceInfo&) override {
    return make_handle(1);
  }
  R<void> claim_interface(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t) override {
    return {};
  }
  R<void> release_interface(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t) override {
    return {};
  }
  R<void> set_alt_setting(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t,
                          std::uint8_t) override {
    return fail(UsbError::Code::NOT_SUPPORTED);
  }
  R<bool> kernel_driver_active(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t) override {
    return false;
  }
  R<void> detach_kernel_driver(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t) override {
    return fail(UsbError::Code::NOT_FOUND);
  }
  R<void> attach_kernel_driver(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t) override {
    return fail(UsbError::Code::NOT_FOUND);
  }
  R<void> reset_device(const orthoflow::drivers::UsbDeviceHandle&) override { return {}; }
  R<void> clear_halt(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t) override {
    return {};
  }
  R<std::size_t> control(const orthoflow::drivers::UsbDeviceHandle&,
                         const orthoflow::drivers::UsbControlSetup&, std::span<std::byte>,
                         orthoflow::drivers::UsbTimeout) override {
    return fail(UsbError::Code::NOT_SUPPORTED);
  }
  R<std::size_t> bulk(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t,
                      std::span<std::byte>, orthoflow::drivers::UsbTimeout) override {
    return fail(UsbError::Code::NOT_FOUND);
  }
  R<std::size_t> interrupt(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t endpoint,
                           std::span<std::byte> data,
                           orthoflow::drivers::UsbTimeout timeout) override {
    constexpr std::int64_t LATENCY = sim::SimJacoTransportConfig{}.transfer_latency.count();
    if (endpoint == jaco::EP_OUT) {
      if (next_ >= trace_.packets.size() || data.size() != jaco::PACKET_BYTES) {
        return fail(UsbError::Code::NO_DEVICE);  // past the trace (the destructor's stop)
      }
      const SentPacket& p = trace_.packets[next_];
      diverged_ = diverged_ || clock_.now_ns() != p.t_ns ||
                  !std::equal(data.begin(), data.end(), p.bytes.begin());
      clock_.set_ns(clock_.now_ns() + LATENCY);
      pending_ = true;
      return jaco::PACKET_BYTES;
    }
    if (!pending_) {  // the flush at open: nothing queued, the read times out
      clock_.set_ns(clock_.now_ns() + std::chrono::nanoseconds(timeout).count());
      return fail(UsbError::Code::TIMEOUT);
    }
    pending_ = false;
    const jaco::Packet& reply = trace_.replies[next_++];
    std::copy(reply.begin(), reply.end(), data.begin());
    clock_.set_ns(clock_.now_ns() + LATENCY);
    return jaco::PACKET_BYTES;
  }
  R<std::size_t> max_iso_packet_size(const orthoflow::drivers::UsbDeviceHandle&,
                                     std::uint8_t) override {
    return fail(UsbError::Code::NOT_FOUND);
  }
  R<void> start_iso(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t,
                    const orthoflow::drivers::UsbIsoConfig&,
                    orthoflow::drivers::UsbIsoCallback) override {
    return fail(UsbError::Code::NOT_FOUND);
  }
  R<void> stop_iso(const orthoflow::drivers::UsbDeviceHandle&, std::uint8_t) override {
    return fail(UsbError::Code::NOT_FOUND);
  }
  R<orthoflow::drivers::UsbIsoStats> iso_stats(const orthoflow::drivers::UsbDeviceHandle&,
                                               std::uint8_t) const override {
    return fail(UsbError::Code::NOT_FOUND);
  }
  R<void> handle_events(orthoflow::drivers::UsbTimeout timeout) override {
    clock_.set_ns(clock_.now_ns() + std::chrono::nanoseconds(timeout).count());
    return {};
  }
  const orthoflow::drivers::MonotonicClock& clock() const noexcept override { return clock_; }

 protected:
  void close_device(std::uint32_t) noexcept override {}

 private:
  const Trace& trace_;
  orthoflow::drivers::ManualClock clock_{0};
  std::size_t next_ = 0;
  bool pending_ = false;
  bool diverged_ = false;
};

/// The driver on canned replies: the same cycles as DirectRig with no simulator under them.
struct CannedRig {
  explicit CannedRig(const Trace& trace) : usb(trace) {
    auto devices = jaco::list_arms(usb);
    if (!devices || devices.value().empty()) return;
    auto opened = jaco::JacoController::open(usb, devices.value().front());
    if (!opened) return;
    controller = std::move(opened).value();
    next_ns = usb.clock().now_ns();
  }
  [[nodiscard]] bool ok() const { return controller != nullptr && !usb.diverged(); }
  void cycle() {
    controller->keep_alive();
    controller->cycle();
    next_ns += PERIOD_NS;
    usb.advance_to(next_ns);
    next_ns = std::max(next_ns, usb.clock().now_ns());
  }
  bool submit(const jaco::ArmCommand& c) { return controller->submit(c).has_value(); }

  CannedTransport usb;  // destroyed after the controller
  std::unique_ptr<jaco::JacoController> controller;
  std::int64_t next_ns = 0;
};

/// The arm model alone: SimJacoArm::receive at the OUT's end, step to the IN's end, take_reply;
/// step to each cycle's boundary (what SimJacoTransport does under the transfers).
class ArmReplay {
 public:
  bool reset(const Trace& trace) {
    arm_ = std::make_unique<sim::SimJacoArm>(JacoRig::home_config(), 0);
    trace_ = &trace;
    ok_ = true;
    for (std::size_t i = 0; i < trace.startup; ++i) exchange(trace.packets[i]);
    return ok_;
  }
  void run(std::size_t first_cycle, std::size_t end_cycle) {
    for (std::size_t c = first_cycle; c < end_cycle; ++c) {
      for (std::size_t i = trace_->begin(c); i < trace_->cycle_end[c]; ++i) {
        exchange(trace_->packets[i]);
      }
      arm_->step(trace_->boundary[c]);
    }
  }
  [[nodiscard]] bool ok() const { return ok_; }
  [[nodiscard]] const sim::SimJacoArm& arm() const { return *arm_; }

 private:
  void exchange(const SentPacket& p) {
    constexpr std::int64_t LATENCY = sim::SimJacoTransportConfig{}.transfer_latency.count();
    arm_->receive(p.bytes, p.t_ns + LATENCY);
    arm_->step(p.t_ns + 2 * LATENCY);
    if (!arm_->has_reply()) {
      ok_ = false;
      return;
    }
    jaco::Packet reply = arm_->take_reply();
    benchmark::DoNotOptimize(reply);
  }

  std::unique_ptr<sim::SimJacoArm> arm_;
  const Trace* trace_ = nullptr;
  bool ok_ = false;
};

bool same_arm(const sim::SimJacoArm& a, const sim::SimJacoArm& b) {
  return a.joints() == b.joints() && a.fingers() == b.fingers() &&
         a.counters().packets == b.counters().packets &&
         a.counters().points_queued == b.counters().points_queued && a.now_ns() == b.now_ns();
}

// ---- 1. one cycle, with and without the simulator -----------------------------------------------

void BM_JacoCycle(benchmark::State& state) {
  const Trace& trace = captured_trace();
  if (trace.cycles() == 0) {
    state.SkipWithError("could not capture the trace on the simulator");
    return;
  }
  std::unique_ptr<DirectRig> rig;
  std::unique_ptr<CannedRig> canned;
  Schedule schedule, canned_schedule;
  TransportReplay transport_replay;
  ArmReplay arm_replay;
  const auto restart = [&] {
    rig = std::make_unique<DirectRig>();
    canned.reset();
    canned = std::make_unique<CannedRig>(trace);
    schedule = canned_schedule = Schedule{};
    return rig->ok() && rig->submit(schedule.next()) && canned->ok() &&
           canned->submit(canned_schedule.next()) && transport_replay.reset(trace) &&
           arm_replay.reset(trace);
  };
  if (!restart()) {
    state.SkipWithError("could not start the rigs");
    return;
  }
  std::size_t c = 0, block_start = 0, cycles = 0, packets = 0;
  std::int64_t cycle_ns = 0, canned_ns = 0, transport_ns = 0, arm_ns = 0;
  std::int64_t block_t0 = thread_cpu_ns();
  bool diverged = false;
  // Times the block of driver cycles on the simulator that just ended; then runs the same cycles
  // on canned replies (the driver alone), through SimJacoTransport and into SimJacoArm.
  const auto close_block = [&] {
    const std::int64_t t1 = thread_cpu_ns();
    cycle_ns += t1 - block_t0;
    for (std::size_t k = block_start; k < c; ++k) {
      canned->cycle();
      if (trace.submit_after[k]) {
        const std::int64_t s0 = thread_cpu_ns();
        diverged = diverged || !canned->submit(canned_schedule.next());
        canned_ns -= thread_cpu_ns() - s0;
      }
    }
    const std::int64_t t2 = thread_cpu_ns();
    transport_replay.run(block_start, c);
    const std::int64_t t3 = thread_cpu_ns();
    arm_replay.run(block_start, c);
    const std::int64_t t4 = thread_cpu_ns();
    canned_ns += t2 - t1;
    transport_ns += t3 - t2;
    arm_ns += t4 - t3;
    cycles += c - block_start;
    packets += trace.cycle_end[c - 1] - trace.begin(block_start);
    block_start = c;
    diverged = diverged || !canned->ok() || !transport_replay.ok() || !arm_replay.ok() ||
               !same_arm(rig->arm(), transport_replay.arm()) ||
               !same_arm(rig->arm(), arm_replay.arm());
  };
  for (auto _ : state) {
    rig->cycle();
    if (schedule.went_idle(rig->arm())) {
      state.PauseTiming();
      const std::int64_t t0 = thread_cpu_ns();
      const bool accepted = rig->submit(schedule.next());
      cycle_ns -= thread_cpu_ns() - t0;
      state.ResumeTiming();
      if (!accepted) {
        state.SkipWithError("a scheduled move was refused");
        break;
      }
    }
    ++c;
    if (c % BLOCK == 0 || c == trace.cycles()) {
      state.PauseTiming();
      close_block();
      if (c == trace.cycles()) {
        if (!restart()) diverged = true;
        c = block_start = 0;
      }
      state.ResumeTiming();
      block_t0 = thread_cpu_ns();
      if (diverged) break;
    }
  }
  if (c > block_start) close_block();
  if (diverged) {
    state.SkipWithError("the replays diverged from the driver's run (not the same packets)");
    return;
  }
  const double n = static_cast<double>(std::max<std::size_t>(cycles, 1));
  const double cycle_us = static_cast<double>(cycle_ns) * 1e-3 / n;
  const double driver_us = static_cast<double>(canned_ns) * 1e-3 / n;
  const double sim_us = static_cast<double>(transport_ns) * 1e-3 / n;
  const double arm_us = static_cast<double>(arm_ns) * 1e-3 / n;
  state.SetItemsProcessed(state.iterations());         // items/s = cycles/s
  state.counters["cycle_us"] = cycle_us;               // driver + the simulator under it
  state.counters["driver_us"] = driver_us;             // the driver on canned replies: no simulator
  state.counters["sim_us"] = sim_us;                   // SimJacoTransport + arm alone, same packets
  state.counters["sim_arm_us"] = arm_us;               // SimJacoArm alone, same packets
  state.counters["cycle-sim_us"] = cycle_us - sim_us;  // the other estimate of driver_us
  state.counters["driver/sim"] = sim_us > 0.0 ? driver_us / sim_us : 0.0;
  state.counters["driver_%core_100Hz"] = 100.0 * driver_us / PERIOD_US;
  state.counters["cycle_%core_100Hz"] = 100.0 * cycle_us / PERIOD_US;
  state.counters["pkts/cycle"] = static_cast<double>(packets) / n;
}

/// One part alone on the trace, as its own benchmark: 0 = the driver on canned replies (no
/// simulator), 1 = SimJacoTransport + arm, 2 = SimJacoArm.
void BM_ReplayCycle(benchmark::State& state) {
  const Trace& trace = captured_trace();
  if (trace.cycles() == 0) {
    state.SkipWithError("could not capture the trace on the simulator");
    return;
  }
  const auto mode = state.range(0);
  std::unique_ptr<CannedRig> canned;
  Schedule schedule;
  TransportReplay transport_replay;
  ArmReplay arm_replay;
  const auto reset = [&] {
    switch (mode) {
      case 0:
        canned.reset();
        canned = std::make_unique<CannedRig>(trace);
        schedule = Schedule{};
        return canned->ok() && canned->submit(schedule.next());
      case 1:
        return transport_replay.reset(trace);
      default:
        return arm_replay.reset(trace);
    }
  };
  const auto healthy = [&] {
    return mode == 0 ? canned->ok() : mode == 1 ? transport_replay.ok() : arm_replay.ok();
  };
  if (!reset()) {
    state.SkipWithError("could not start the replay");
    return;
  }
  std::size_t c = 0;
  for (auto _ : state) {
    if (mode == 0) {
      canned->cycle();
      if (trace.submit_after[c]) {
        state.PauseTiming();
        (void)canned->submit(schedule.next());
        state.ResumeTiming();
      }
    } else if (mode == 1) {
      transport_replay.run(c, c + 1);
    } else {
      arm_replay.run(c, c + 1);
    }
    if (++c == trace.cycles()) {
      state.PauseTiming();
      if (!healthy() || !reset()) {
        state.SkipWithError("the replay failed or diverged");
        break;
      }
      c = 0;
      state.ResumeTiming();
    }
  }
  if (!healthy()) state.SkipWithError("the replay failed or diverged");
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(mode == 0   ? "driver on canned replies"
                 : mode == 1 ? "SimJacoTransport+arm"
                             : "SimJacoArm");
}

// ---- 2. command to USB, and submit() ------------------------------------------------------------

struct LatencySample {
  double latency_ms = 0.0;  // submit -> the OUT transfer of the first 308 starts
  std::size_t ahead = 0;    // OUT packets sent before it in its cycle
};

/// A fresh rig; @p idle_cycles cycles; one more cycle; the command submitted @p phase_ns after
/// that cycle ended (clamped to the next cycle's start); cycles until the first trajectory point.
std::optional<LatencySample> latency_once(int idle_cycles, std::int64_t phase_ns,
                                          std::int64_t* window_ns) {
  try {
    JacoRig rig;
    for (int i = 0; i < idle_cycles; ++i) rig.cycle(true);
    rig.controller->keep_alive();
    rig.controller->cycle();
    const std::int64_t boundary = rig.next_ns + PERIOD_NS;
    *window_ns = boundary - rig.now();
    const std::int64_t t_submit = std::min(rig.now() + phase_ns, boundary);
    if (t_submit > rig.now()) rig.sim.run_for(std::chrono::nanoseconds(t_submit - rig.now()));
    if (!rig.controller->submit(move_to(goal_a()))) return std::nullopt;
    if (boundary > rig.now()) rig.sim.run_for(std::chrono::nanoseconds(boundary - rig.now()));
    rig.next_ns = boundary;
    for (int k = 0; k < 4; ++k) {
      const std::size_t first = rig.recorder.sent.size();
      rig.cycle(true);
      for (std::size_t i = first; i < rig.recorder.sent.size(); ++i) {
        const SentPacket& p = rig.recorder.sent[i];
        if (p.command() != jaco::Command::SEND_BASIC_TRAJECTORY) continue;
        return LatencySample{static_cast<double>(p.t_ns - t_submit) * 1e-6, i - first};
      }
    }
  } catch (const std::exception&) {}
  return std::nullopt;
}

void BM_CommandToUsbLatency(benchmark::State& state) {
  std::vector<LatencySample> samples;
  for (auto _ : state) {
    samples.clear();
    for (int idle = 0; idle < 10; ++idle) {  // every slow-read slot (cycle % 10) once
      std::int64_t window = PERIOD_NS;
      for (std::int64_t phase = 0; phase <= window; phase += 1'000'000) {
        auto s = latency_once(idle, phase, &window);
        if (!s) {
          state.SkipWithError("no trajectory point within 4 cycles of the command");
          return;
        }
        samples.push_back(*s);
      }
    }
  }
  double sum = 0.0, lo = 1e9, hi = 0.0;
  std::size_t ahead = 0;
  for (const auto& s : samples) {
    sum += s.latency_ms;
    lo = std::min(lo, s.latency_ms);
    hi = std::max(hi, s.latency_ms);
    ahead = std::max(ahead, s.ahead);
  }
  const double latency_ms =
      static_cast<double>(sim::SimJacoTransportConfig{}.transfer_latency.count()) * 1e-6;
  state.counters["lat_min_ms"] = lo;
  state.counters["lat_mean_ms"] = sum / static_cast<double>(samples.size());
  state.counters["lat_max_ms"] = hi;
  state.counters["at_arm_max_ms"] = hi + latency_ms;  // the OUT reaches the arm 1 ms later
  state.counters["pkts_ahead_max"] = static_cast<double>(ahead);
  state.counters["samples"] = static_cast<double>(samples.size());
  state.SetLabel("simulated time, deterministic");
}

/// CPU of submit(): 0 = MOVE_JOINTS, 1 = MOVE_POSE near the seed, 2 = MOVE_POSE 120 degrees away.
void BM_Submit(benchmark::State& state) {
  std::optional<JacoRig> rig;
  try {
    rig.emplace();
  } catch (const std::exception&) {
    state.SkipWithError("could not start the rig");
    return;
  }
  const jaco::JointAngles near = offset(home(), {-15.0, 10.0, -10.0, 20.0, 10.0, -25.0});
  const jaco::JointAngles far = offset(home(), {120.0, 0.0, 0.0, 0.0, 0.0, 0.0});
  std::array<jaco::ArmCommand, 2> commands;
  switch (state.range(0)) {
    case 0:
      commands = {move_to(goal_a()), move_to(near)};
      state.SetLabel("MOVE_JOINTS");
      break;
    case 1:
      commands = {move_pose(near), move_pose(offset(near, {1.0, 1.0, 1.0, 1.0, 1.0, 1.0}))};
      state.SetLabel("MOVE_POSE near");
      break;
    default:
      commands = {move_pose(far), move_pose(offset(far, {1.0, 1.0, 1.0, 1.0, 1.0, 1.0}))};
      state.SetLabel("MOVE_POSE far (IK restarts)");
      break;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    auto accepted = rig->controller->submit(commands[i++ & 1U]);
    if (!accepted) {
      state.SkipWithError(("refused: " + jaco::to_string(accepted.error())).c_str());
      break;
    }
  }
}

// ---- 3. the threaded arm's state stream ---------------------------------------------------------

double load_average() {
  std::ifstream in("/proc/loadavg");
  double load = 0.0;
  in >> load;
  return load;
}

void BM_StateStreamJitter(benchmark::State& state) {
  const std::chrono::milliseconds wall(state.range(0));
  std::vector<std::int64_t> stamps;
  stamps.reserve(static_cast<std::size_t>(wall.count() / 10) * 2 + 256);
  jaco::ArmSnapshot last{};
  double sim_s = 0.0, wall_s = 0.0;
  const double load = load_average();
  for (auto _ : state) {
    stamps.clear();
    auto transport = std::make_unique<sim::SimJacoTransport>();
    transport->add_arm(JacoRig::home_config());
    auto devices = jaco::list_arms(*transport);
    if (!devices || devices.value().empty()) {
      state.SkipWithError("no simulated arm");
      return;
    }
    jaco::ArmOptions options;
    options.pace_to_wall_clock = true;
    // USB thread only; read here after the arm (and its thread) is gone.
    options.subscribers.push_back([&stamps](const jaco::ArmSnapshot&) {
      if (stamps.size() < stamps.capacity()) stamps.push_back(steady_ns());
    });
    auto started = jaco::JacoArm::start(std::move(transport), devices.value().front(), options);
    if (!started) {
      state.SkipWithError(("start: " + jaco::to_string(started.error())).c_str());
      return;
    }
    std::unique_ptr<jaco::JacoArm> arm = std::move(started).value();
    const std::int64_t sim0 = arm->now_ns();
    const auto t0 = std::chrono::steady_clock::now();
    Schedule schedule;
    std::uint64_t submitted_at = 0;
    (void)arm->submit(schedule.next());
    while (std::chrono::steady_clock::now() - t0 < wall) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      arm->keep_alive();
      const jaco::ArmSnapshot s = arm->snapshot();
      if (s.control == jaco::ControlState::IDLE && s.cycle > submitted_at + 2) {
        (void)arm->submit(schedule.next());
        submitted_at = s.cycle;
      }
    }
    last = arm->snapshot();
    sim_s = static_cast<double>(arm->now_ns() - sim0) * 1e-9;
    wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    arm.reset();  // joins the USB thread
  }
  if (stamps.size() < 3) {
    state.SkipWithError("too few snapshots");
    return;
  }
  std::vector<double> dev;
  std::size_t short_periods = 0;
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    const double period_ms = static_cast<double>(stamps[i] - stamps[i - 1]) * 1e-6;
    dev.push_back(std::abs(period_ms - 10.0));
    if (period_ms < 5.0) ++short_periods;
  }
  std::sort(dev.begin(), dev.end());
  const auto pct = [&](double p) {
    return dev[std::min(dev.size() - 1,
                        static_cast<std::size_t>(p * static_cast<double>(dev.size())))];
  };
  state.counters["periods"] = static_cast<double>(dev.size());
  state.counters["mean_period_ms"] =
      static_cast<double>(stamps.back() - stamps.front()) * 1e-6 / static_cast<double>(dev.size());
  state.counters["dev_p50_ms"] = pct(0.50);
  state.counters["dev_p99_ms"] = pct(0.99);
  state.counters["dev_max_ms"] = dev.back();
  state.counters["periods_under_5ms"] = static_cast<double>(short_periods);
  state.counters["sim/wall"] = wall_s > 0.0 ? sim_s / wall_s : 0.0;
  state.counters["overruns"] = static_cast<double>(last.cycles_overrun);
  state.counters["watchdog_stops"] = static_cast<double>(last.watchdog_stops);
  state.counters["loadavg_1min"] = load;
}

// ---- 4. kinematics ------------------------------------------------------------------------------

void BM_ForwardKinematics(benchmark::State& state) {
  jaco::JointAngles q = goal_a();
  for (auto _ : state) {
    benchmark::DoNotOptimize(q);
    Eigen::Isometry3d t = jaco::forward_kinematics(q);
    benchmark::DoNotOptimize(t);
  }
}

/// What read_state() runs every cycle: FK and the arm's Euler pose.
void BM_FkToPose(benchmark::State& state) {
  jaco::JointAngles q = goal_a();
  for (auto _ : state) {
    benchmark::DoNotOptimize(q);
    jaco::CartesianPose pose = jaco::to_pose(jaco::forward_kinematics(q));
    benchmark::DoNotOptimize(pose);
  }
}

/// 0 = target 40 deg (joint-space norm) from the seed, 1 = a base turn of 120 deg (the seed's
/// solution lies beyond 60 deg: every restart runs), 2 = unreachable inside the reach sphere.
void BM_InverseKinematics(benchmark::State& state) {
  const jaco::JointAngles seed = home();
  const jaco::JointLimits limits = jaco::jaco_joint_limits();
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  switch (state.range(0)) {
    case 0:
      target = jaco::forward_kinematics(offset(seed, {-15.0, 10.0, -10.0, 20.0, 10.0, -25.0}));
      state.SetLabel("near");
      break;
    case 1:
      target = jaco::forward_kinematics(offset(seed, {120.0, 0.0, 0.0, 0.0, 0.0, 0.0}));
      state.SetLabel("far");
      break;
    default:
      target.translation() = Eigen::Vector3d(0.0, 0.0, 0.05);  // inside the base, 5 cm up
      state.SetLabel("unreachable");
      break;
  }
  bool solved = false;
  double distance = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(target);
    auto q = jaco::inverse_kinematics(target, seed, limits);
    solved = q.has_value();
    if (solved) {
      double d2 = 0.0;
      for (std::size_t j = 0; j < 6; ++j) d2 += (q.value()[j] - seed[j]) * (q.value()[j] - seed[j]);
      distance = std::sqrt(d2);
    }
    benchmark::DoNotOptimize(q);
  }
  state.counters["solved"] = solved ? 1.0 : 0.0;
  state.counters["dist_deg"] = distance;
}

// The safety monitor's sweep of a whole move (submit time): stretches examined.
void BM_CheckJointMove(benchmark::State& state) {
  const jaco::SafetyLimits limits;
  const jaco::JointAngles from = home(), to = goal_a();
  jaco::MonitorCost cost;
  for (auto _ : state) {
    auto ok = jaco::check_joint_move(limits, from, to, 0.0, {}, &cost);
    benchmark::DoNotOptimize(ok);
  }
  state.counters["stretches"] = static_cast<double>(cost.nodes);
}

}  // namespace

BENCHMARK(BM_JacoCycle)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ReplayCycle)->DenseRange(0, 2)->ArgName("part")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CommandToUsbLatency)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Submit)->DenseRange(0, 2)->ArgName("kind")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StateStreamJitter)
    ->Arg(2000)
    ->ArgName("wall_ms")
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ForwardKinematics)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_FkToPose)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_InverseKinematics)->DenseRange(0, 2)->ArgName("case")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CheckJointMove)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
