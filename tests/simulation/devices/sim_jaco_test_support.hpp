#pragma once
// Helpers for the simulated-JACO tests: a SimJacoTransport with one arm opened and claimed, spoken
// to only through the UsbTransport interface with packets built by drivers/jaco/jaco_protocol.hpp
// (no driver code above the codec). The protocol tests run the ideal arm (speeds jump, a packet
// acts at the next cycle: SimJacoDynamics::ideal()); the arm's physics has its own tests
// (sim_jaco_dynamics_test.cpp).
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>

#include "simulation/devices/sim_jaco_transport.hpp"

namespace orthoflow::simulation::test {

namespace jaco = drivers::jaco;
using drivers::UsbDeviceHandle;
using drivers::UsbDeviceInfo;
using drivers::UsbError;
using drivers::UsbTimeout;
using Code = UsbError::Code;
using namespace std::chrono_literals;

inline constexpr UsbTimeout TIMEOUT_1S{1000};
inline constexpr std::int64_t MS = 1'000'000;

/// A JACO2 already at HOME (READY_STANDBY), the ideal arm.
inline SimJacoConfig ready_config() {
  SimJacoConfig c;
  c.start_state = jaco::ArmState::READY_STANDBY;
  c.dynamics = SimJacoDynamics::ideal();
  return c;
}

/// One arm on a transport, opened and interface 0 claimed.
struct JacoRig {
  SimJacoTransport usb;
  UsbDeviceHandle h;

  explicit JacoRig(SimJacoConfig config = ready_config(), SimJacoTransportConfig t = {},
                   bool ideal = true)
      : usb(t) {
    if (ideal) config.dynamics = SimJacoDynamics::ideal();
    usb.add_arm(std::move(config));
    auto list = usb.enumerate(jaco::VENDOR_KINOVA, jaco::PID_JACO);
    EXPECT_TRUE(list && list->size() == 1);
    auto opened = usb.open(list->front());
    EXPECT_TRUE(opened);
    h = std::move(*opened);
    EXPECT_TRUE(usb.claim_interface(h, 0));
  }
  SimJacoArm& arm() { return usb.arm(0); }
  std::int64_t now() const { return usb.clock().now_ns(); }

  Result<std::size_t, UsbError> write(jaco::Packet packet) {
    return usb.interrupt(h, jaco::EP_OUT, packet, TIMEOUT_1S);
  }
  Result<std::size_t, UsbError> read(jaco::Packet& reply, UsbTimeout timeout = TIMEOUT_1S) {
    return usb.interrupt(h, jaco::EP_IN, reply, timeout);
  }
  /// OUT then IN; nullopt (and a test failure if @p must) when either transfer fails.
  std::optional<jaco::Packet> exchange(const jaco::Packet& out, bool must = true) {
    const auto w = write(out);
    EXPECT_TRUE(w) << "OUT failed";
    jaco::Packet reply{};
    const auto r = read(reply);
    if (must) { EXPECT_TRUE(r) << "IN failed: " << (r ? "" : drivers::to_string(r.error().code)); }
    if (!w || !r) return std::nullopt;
    return reply;
  }
  std::optional<jaco::Packet> get(jaco::Command command, std::uint16_t slice = 1) {
    return exchange(jaco::make_request(command, slice));
  }
  void plain(jaco::Command command) { exchange(jaco::make_plain_command(command)); }
  void joystick(const jaco::JoystickState& state) { exchange(jaco::encode_joystick(state)); }
  void point(const jaco::TrajectoryPoint& p) { exchange(jaco::encode_trajectory(p)); }
  /// The retract mode through command 62 (DSP >= 5).
  jaco::ArmState status_state() {
    jaco::ArmStatus status;
    const auto reply = get(jaco::Command::GET_ARM_STATUS);
    EXPECT_TRUE(reply && jaco::parse_arm_status(*reply, status) == jaco::PacketCheck::OK);
    return status.state;
  }
  jaco::NineFloats nine(jaco::Command command) {
    jaco::NineFloats out;
    const auto reply = get(command);
    EXPECT_TRUE(reply && jaco::parse_nine(*reply, out) == jaco::PacketCheck::OK);
    return out;
  }
  /// Lets simulated time pass without traffic.
  void wait(std::chrono::nanoseconds d) { usb.run_for(d); }
};

/// x, y, z, theta x, y, z of @p pose, in the order of a 104 reply.
inline std::array<double, 6> pose6(const jaco::CartesianPose& pose) {
  return {pose.position.x(), pose.position.y(), pose.position.z(),
          pose.theta.x(),    pose.theta.y(),    pose.theta.z()};
}

inline jaco::JoystickState axes(std::size_t axis, float value) {
  jaco::JoystickState s;
  s.axes[axis] = value;
  return s;
}

inline jaco::TrajectoryPoint angular_position(const jaco::JointAngles& target) {
  jaco::TrajectoryPoint p;
  for (std::size_t j = 0; j < jaco::JOINTS; ++j) p.target[j] = static_cast<float>(target[j]);
  p.hand_mode = jaco::HandMode::NO_MOVEMENT;
  p.type = jaco::PositionType::ANGULAR_POSITION;
  return p;
}

inline jaco::TrajectoryPoint angular_velocity(std::size_t joint, float deg_s) {
  jaco::TrajectoryPoint p;
  p.target[joint] = deg_s;
  p.hand_mode = jaco::HandMode::NO_MOVEMENT;
  p.type = jaco::PositionType::ANGULAR_VELOCITY;
  return p;
}

}  // namespace orthoflow::simulation::test
