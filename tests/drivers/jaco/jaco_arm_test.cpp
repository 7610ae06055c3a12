// The threaded JACO arm (drivers/jaco/jaco_arm.hpp) on the simulated arm, and the real-time rule
// for its control loop: after warm-up, JacoController::cycle() allocates nothing, streaming or
// homing.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "drivers/jaco/jaco_arm.hpp"
#include "jaco_test_rig.hpp"
#include "tests/support/counting_new.hpp"  // the one TU of this binary that replaces operator new

namespace orthoflow::test {
namespace {

using jaco::ArmCommand;

TEST(JacoControllerAllocations, CycleAllocatesNothingWhileStreamingOrHoming) {
  simulation::SimJacoConfig config;  // NOINIT: home first, then move
  JacoRig rig(config);
  rig.recorder.recording = false;  // the recorder's vector would allocate
  ArmCommand home;
  home.kind = ArmCommand::Kind::HOME;
  ASSERT_TRUE(rig.controller->submit(home).has_value());
  for (int i = 0; i < 5; ++i) rig.cycle(true);  // warm-up
  g_allocations = 0;
  g_counted_thread = std::this_thread::get_id();
  g_counting = true;
  const int homing = rig.run_until_idle(3000);
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0U) << "while homing";
  ASSERT_GT(homing, 0);
  ASSERT_EQ(rig.arm().state(), jaco::ArmState::READY_STANDBY);

  ArmCommand move;
  move.kind = ArmCommand::Kind::MOVE_JOINTS;
  move.joints = rig.arm().joints();
  move.joints[0] += 15.0;
  move.joints[5] -= 20.0;
  ASSERT_TRUE(rig.controller->submit(move).has_value());
  rig.cycle(true);
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < 200; ++i) rig.cycle(true);  // streaming, slow reads included
  g_counting = false;
  g_counted_thread = std::thread::id{};
  EXPECT_EQ(g_allocations.load(), 0U) << "while streaming";
}

std::unique_ptr<jaco::JacoArm> start_sim_arm(jaco::ArmOptions options) {
  auto sim = std::make_unique<simulation::SimJacoTransport>();
  simulation::SimJacoConfig config;
  config.start_state = jaco::ArmState::READY_STANDBY;
  sim->add_arm(config);
  auto devices = jaco::list_arms(*sim);
  EXPECT_TRUE(devices.has_value());
  auto arm = jaco::JacoArm::start(std::move(sim), devices.value().front(), std::move(options));
  EXPECT_TRUE(arm.has_value());
  return arm.has_value() ? std::move(arm).value() : nullptr;
}

// Paced to the wall clock, the arm streams a snapshot every 10 ms to its subscribers, and a client
// on another thread moves it by submitting once and feeding the watchdog.
TEST(JacoArm, StreamsStateAt100HzAndMovesForAClientThread) {
  std::atomic<std::uint64_t> callbacks{0};
  std::atomic<std::uint64_t> last_cycle{0};
  std::atomic<bool> in_order{true};
  jaco::ArmOptions options;
  options.pace_to_wall_clock = true;
  options.subscribers.push_back([&](const jaco::ArmSnapshot& s) {
    if (s.cycle <= last_cycle.load()) in_order = false;
    last_cycle = s.cycle;
    ++callbacks;
  });
  auto arm = start_sim_arm(std::move(options));
  ASSERT_NE(arm, nullptr);
  ArmCommand move;
  move.kind = ArmCommand::Kind::MOVE_JOINTS;
  move.joints = arm->snapshot().joints;
  move.joints[0] += 5.0;
  ASSERT_TRUE(arm->submit(move).has_value());
  const auto start = std::chrono::steady_clock::now();
  jaco::ArmSnapshot s;
  while (std::chrono::steady_clock::now() - start < std::chrono::seconds(5)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    arm->keep_alive();
    s = arm->snapshot();
    if (s.cycle > 3 && s.control == jaco::ControlState::IDLE) break;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(s.last_stop, jaco::StopReason::REACHED);
  EXPECT_NEAR(s.joints[0], move.joints[0], 0.15);
  EXPECT_TRUE(in_order.load());
  // 100 Hz in wall time, loosely (a loaded CI machine may be slow, never faster).
  const double rate = static_cast<double>(callbacks.load()) / seconds;
  EXPECT_LT(rate, 110.0);
  EXPECT_GT(rate, 50.0);
}

// The emergency stop from another thread while the arm runs on its own thread.
TEST(JacoArm, EmergencyStopFromAnyThread) {
  jaco::ArmOptions options;
  options.pace_to_wall_clock = true;
  auto arm = start_sim_arm(std::move(options));
  ASSERT_NE(arm, nullptr);
  ArmCommand move;
  move.kind = ArmCommand::Kind::MOVE_JOINTS;
  move.joints = arm->snapshot().joints;
  move.joints[0] += 40.0;
  ASSERT_TRUE(arm->submit(move).has_value());
  for (int i = 0; i < 15; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    arm->keep_alive();
  }
  std::thread puller([&] { arm->estop(); });
  puller.join();
  // The simulated arm brakes from about 12 deg/s at 100 deg/s^2 after its 10 ms command latency:
  // at rest well within 400 ms.
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  const auto s = arm->snapshot();
  EXPECT_TRUE(s.estop);
  EXPECT_EQ(s.control, jaco::ControlState::ESTOP);
  EXPECT_EQ(arm->submit(move).error().code, jaco::JacoError::Code::ESTOP);
  const double stopped_at = s.joints[0];
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_NEAR(arm->snapshot().joints[0], stopped_at, 1e-6);
}

}  // namespace
}  // namespace orthoflow::test
