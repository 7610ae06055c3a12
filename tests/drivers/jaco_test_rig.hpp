#pragma once
// The JACO driver's test rig: a JacoController on the simulated arm (simulation/sim_jaco_transport)
// in lock step on simulated time, and a transport decorator that records every packet the driver
// sends, so tests can check what reached the arm ("none outside the limits is ever sent").
#include <chrono>
#include <memory>
#include <stdexcept>
#include <vector>

#include "drivers/jaco_controller.hpp"
#include "simulation/sim_jaco_transport.hpp"

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

/// Forwards every call to a SimJacoTransport and records the OUT packets on 0x02.
class RecordingTransport final : public drivers::UsbTransport {
 public:
  explicit RecordingTransport(simulation::SimJacoTransport& inner) : inner_(inner) {}
  std::vector<SentPacket> sent;

  Result<std::vector<drivers::UsbDeviceInfo>, drivers::UsbError> enumerate(
      std::uint16_t v, std::optional<std::uint16_t> p) override {
    return inner_.enumerate(v, p);
  }
  Result<drivers::UsbDeviceHandle, drivers::UsbError> open(
      const drivers::UsbDeviceInfo& d) override {
    auto h = inner_.open(d);
    if (!h) return err(h.error());
    inner_handles_.push_back(std::move(h).value());
    return make_handle(static_cast<std::uint32_t>(inner_handles_.size()));
  }
  Result<void, drivers::UsbError> claim_interface(const drivers::UsbDeviceHandle& h,
                                                  std::uint8_t i) override {
    return inner_.claim_interface(inner(h), i);
  }
  Result<void, drivers::UsbError> release_interface(const drivers::UsbDeviceHandle& h,
                                                    std::uint8_t i) override {
    return inner_.release_interface(inner(h), i);
  }
  Result<void, drivers::UsbError> set_alt_setting(const drivers::UsbDeviceHandle& h, std::uint8_t i,
                                                  std::uint8_t a) override {
    return inner_.set_alt_setting(inner(h), i, a);
  }
  Result<bool, drivers::UsbError> kernel_driver_active(const drivers::UsbDeviceHandle& h,
                                                       std::uint8_t i) override {
    return inner_.kernel_driver_active(inner(h), i);
  }
  Result<void, drivers::UsbError> detach_kernel_driver(const drivers::UsbDeviceHandle& h,
                                                       std::uint8_t i) override {
    return inner_.detach_kernel_driver(inner(h), i);
  }
  Result<void, drivers::UsbError> attach_kernel_driver(const drivers::UsbDeviceHandle& h,
                                                       std::uint8_t i) override {
    return inner_.attach_kernel_driver(inner(h), i);
  }
  Result<void, drivers::UsbError> reset_device(const drivers::UsbDeviceHandle& h) override {
    return inner_.reset_device(inner(h));
  }
  Result<void, drivers::UsbError> clear_halt(const drivers::UsbDeviceHandle& h,
                                             std::uint8_t e) override {
    return inner_.clear_halt(inner(h), e);
  }
  Result<std::size_t, drivers::UsbError> control(const drivers::UsbDeviceHandle& h,
                                                 const drivers::UsbControlSetup& s,
                                                 std::span<std::byte> d,
                                                 drivers::UsbTimeout t) override {
    return inner_.control(inner(h), s, d, t);
  }
  Result<std::size_t, drivers::UsbError> bulk(const drivers::UsbDeviceHandle& h, std::uint8_t e,
                                              std::span<std::byte> d,
                                              drivers::UsbTimeout t) override {
    return inner_.bulk(inner(h), e, d, t);
  }
  Result<std::size_t, drivers::UsbError> interrupt(const drivers::UsbDeviceHandle& h,
                                                   std::uint8_t e, std::span<std::byte> d,
                                                   drivers::UsbTimeout t) override {
    if (e == jaco::EP_OUT && d.size() == jaco::PACKET_BYTES) {
      SentPacket p;
      p.t_ns = inner_.clock().now_ns();
      std::copy(d.begin(), d.end(), p.bytes.begin());
      if (recording) sent.push_back(p);
    }
    return inner_.interrupt(inner(h), e, d, t);
  }
  Result<std::size_t, drivers::UsbError> max_iso_packet_size(const drivers::UsbDeviceHandle& h,
                                                             std::uint8_t e) override {
    return inner_.max_iso_packet_size(inner(h), e);
  }
  Result<void, drivers::UsbError> start_iso(const drivers::UsbDeviceHandle& h, std::uint8_t e,
                                            const drivers::UsbIsoConfig& c,
                                            drivers::UsbIsoCallback cb) override {
    return inner_.start_iso(inner(h), e, c, std::move(cb));
  }
  Result<void, drivers::UsbError> stop_iso(const drivers::UsbDeviceHandle& h,
                                           std::uint8_t e) override {
    return inner_.stop_iso(inner(h), e);
  }
  Result<drivers::UsbIsoStats, drivers::UsbError> iso_stats(const drivers::UsbDeviceHandle& h,
                                                            std::uint8_t e) const override {
    return inner_.iso_stats(inner_handles_.at(h.id() - 1), e);
  }
  Result<void, drivers::UsbError> handle_events(drivers::UsbTimeout t) override {
    return inner_.handle_events(t);
  }
  const drivers::MonotonicClock& clock() const noexcept override { return inner_.clock(); }
  bool recording = true;

 protected:
  void close_device(std::uint32_t id) noexcept override {
    if (id >= 1 && id <= inner_handles_.size()) inner_.close(inner_handles_[id - 1]);
  }

 private:
  const drivers::UsbDeviceHandle& inner(const drivers::UsbDeviceHandle& h) const {
    static const drivers::UsbDeviceHandle empty;
    if (h.transport() != this || h.id() == 0 || h.id() > inner_handles_.size()) return empty;
    return inner_handles_[h.id() - 1];
  }
  simulation::SimJacoTransport& inner_;
  std::vector<drivers::UsbDeviceHandle> inner_handles_;
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
