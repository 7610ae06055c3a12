#pragma once
// The JACO driver's test rig: a JacoController on the simulated arm
// (simulation/devices/sim_jaco_transport.hpp) in lock step on simulated time, and a transport
// decorator that records every packet the driver sends, so tests can check what reached the arm
// ("none outside the limits is ever sent").
#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <vector>

#include "drivers/jaco/jaco_controller.hpp"
#include "simulation/devices/forwarding_transport.hpp"
#include "simulation/devices/sim_jaco_transport.hpp"

namespace orthoflow::test {

namespace jaco = drivers::jaco;

/// One OUT packet the driver sent, with the simulated time it left.
struct SentPacket {
  std::int64_t t_ns = 0;
  jaco::Packet bytes{};
  [[nodiscard]] jaco::Command command() const {
    return static_cast<jaco::Command>(jaco::read_header(bytes).command_id);
  }
};

/// Forwards every call to a SimJacoTransport (simulation/devices/forwarding_transport.hpp) and
/// records the OUT packets on 0x02, with the simulated time each left, while `recording`.
class RecordingTransport final : public simulation::ForwardingTransport {
 public:
  explicit RecordingTransport(simulation::SimJacoTransport& inner) : ForwardingTransport(inner) {}
  mutable std::vector<SentPacket> sent;  // filled by the (const) hook
  bool recording = true;

 protected:
  void on_call(const simulation::SeamCall& call) const override {
    if (call.done || call.op != simulation::SeamOp::INTERRUPT || call.number != jaco::EP_OUT ||
        call.data.size() != jaco::PACKET_BYTES || !recording)
      return;
    SentPacket p;
    p.t_ns = clock().now_ns();
    std::copy(call.data.begin(), call.data.end(), p.bytes.begin());
    sent.push_back(p);
  }
};

/// A controller on one simulated arm, stepped by hand: cycle() runs one period and then advances
/// simulated time to the next 10 ms boundary, as JacoArm's thread does.
struct JacoRig {
  explicit JacoRig(simulation::SimJacoConfig config = home_config(),
                   jaco::ControllerOptions options = {}) {
    sim.add_arm(std::move(config));
    auto devices = jaco::list_arms(recorder);
    if (!devices || devices.value().empty()) throw std::runtime_error("no simulated arm");
    device = devices.value().front();
    auto opened = jaco::JacoController::open(recorder, device, options);
    if (!opened) throw std::runtime_error("open: " + jaco::to_string(opened.error()));
    controller = std::move(opened).value();
    next_ns = sim.clock().now_ns();
  }
  static simulation::SimJacoConfig home_config() {
    simulation::SimJacoConfig c;
    c.start_state = jaco::ArmState::READY_STANDBY;
    return c;
  }
  simulation::SimJacoArm& arm() { return sim.arm(0); }
  std::int64_t now() const { return sim.clock().now_ns(); }

  /// One control period. With @p feed the client feeds the watchdog first.
  void cycle(bool feed = false) {
    if (feed) controller->keep_alive();
    controller->cycle();
    next_ns += jaco::ARM_PERIOD_NS;
    if (now() < next_ns) sim.run_for(std::chrono::nanoseconds(next_ns - now()));
    next_ns = std::max(next_ns, now());
  }
  /// Cycles (feeding the watchdog) until the controller is idle again or @p max cycles ran.
  int run_until_idle(int max, bool feed = true) {
    for (int i = 0; i < max; ++i) {
      cycle(feed);
      const auto s = controller->snapshot();
      if (i > 1 && s.control == jaco::ControlState::IDLE) return i + 1;
      if (s.fault) return -1;
    }
    return max;
  }

  simulation::SimJacoTransport sim;
  RecordingTransport recorder{sim};
  drivers::UsbDeviceInfo device{};
  std::unique_ptr<jaco::JacoController> controller;
  std::int64_t next_ns = 0;
};

}  // namespace orthoflow::test
