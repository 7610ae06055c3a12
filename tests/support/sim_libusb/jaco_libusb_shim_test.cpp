// The JACO driver (drivers/jaco/jaco_controller.hpp over drivers/usb/libusb_transport.hpp) end to
// end against the simulated arm inside the sim_libusb shim: the binary links the real libusb-1.0;
// CTest starts it with LD_LIBRARY_PATH=<the shim's directory>, so every libusb call (the driver's
// and the raw ones below) reaches the shim, which hosts simulation::SimJacoArm behind
// libusb_interrupt_transfer. Each test sets ORTHOFLOW_SIM_JACO / ORTHOFLOW_SIM_KINECT before its
// libusb_init (the shim builds its bus at the first libusb_init after the last libusb_exit). The
// arm runs in real time (README "JACO"), so the controller is cycled as JacoArm::run does: one
// cycle per 10 ms of the transport's steady clock, waiting in handle_events in between. What the
// arm did is read back through the driver (command 15 reports the simulator's true joints).
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <libusb-1.0/libusb.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <thread>

#include "drivers/jaco/jaco_arm.hpp"
#include "drivers/jaco/jaco_controller.hpp"
#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/usb/libusb_transport.hpp"
#include "simulation/devices/sim_jaco_arm.hpp"
#include "tests/support/sim_libusb/sim_jaco_env.hpp"
#include "tests/support/sim_libusb/sim_kinect_env.hpp"

namespace orthoflow::drivers::jaco {
namespace {

using namespace std::chrono_literals;
using Kind = ArmCommand::Kind;
using simulation::SimJacoConfig;
using Clock = std::chrono::steady_clock;

// Sets (or, with nullptr, unsets) one environment variable for a scope, and restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    const char* old = std::getenv(name);
    had_ = old != nullptr;
    if (had_) saved_ = old;
    if (value != nullptr) {
      ::setenv(name, value, 1);
    } else {
      ::unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (had_) {
      ::setenv(name_, saved_.c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::string saved_;
  bool had_ = false;
};

// The shim's bus for one test: its Kinects and its arms.
struct SimBus {
  SimBus(const char* kinects, const char* jacos)
      : kinect(sim_libusb::ENV_KINECT, kinects), jaco(sim_libusb::ENV_JACO, jacos) {}
  ScopedEnv kinect;
  ScopedEnv jaco;
};

JointAngles offset(JointAngles q, const std::array<double, JOINTS>& d) {
  for (std::size_t j = 0; j < JOINTS; ++j) q[j] += d[j];
  return q;
}

double max_error(const JointAngles& a, const JointAngles& b) {
  double m = 0.0;
  for (std::size_t j = 0; j < JOINTS; ++j) m = std::max(m, std::abs(a[j] - b[j]));
  return m;
}

ArmCommand move_to(const JointAngles& q, double speed = 1.0) {
  ArmCommand c;
  c.kind = Kind::MOVE_JOINTS;
  c.joints = q;
  c.speed_fraction = speed;
  return c;
}

// A controller on the shimmed arm, cycled as JacoArm::run cycles it: cycle(), then wait on the
// transport until the next 10 ms boundary of its clock (by default in handle_events; a Kinect test
// pumps the camera instead).
struct Rig {
  std::unique_ptr<LibusbTransport> usb;
  std::unique_ptr<JacoController> controller;  // after usb: destroyed first
  std::function<void(UsbTimeout)> wait;
  std::int64_t next_ns = 0;

  // These tests run the controller on the real clock, one cycle per 10 ms, with the watchdog fed
  // every cycle; on a loaded machine (CI, two cores, -j2) one cycle once stalled past the default
  // 100 ms and the watchdog rightly stopped the homing (the watchdog's own tests run on a test
  // clock, tests/drivers). None here tests the watchdog: it gets 1 s.
  static ControllerOptions relaxed_watchdog() {
    ControllerOptions options;
    options.command_timeout_ns = 1'000'000'000;
    return options;
  }
  void open(ControllerOptions options = relaxed_watchdog()) {
    auto usb_result = LibusbTransport::create();
    ASSERT_TRUE(usb_result.has_value()) << to_string(usb_result.error());
    usb = std::move(usb_result).value();
    auto arms = list_arms(*usb);
    ASSERT_TRUE(arms.has_value()) << to_string(arms.error());
    ASSERT_EQ(arms->size(), 1U);
    auto opened = JacoController::open(*usb, arms->front(), options);
    ASSERT_TRUE(opened.has_value()) << to_string(opened.error());
    controller = std::move(opened).value();
    if (!wait) wait = [this](UsbTimeout t) { (void)usb->handle_events(t); };
    next_ns = usb->clock().now_ns();
  }
  void cycle(bool feed = true) {
    if (feed) controller->keep_alive();
    controller->cycle();
    const MonotonicClock& clock = usb->clock();
    next_ns = std::max(next_ns + ARM_PERIOD_NS, clock.now_ns());
    for (int i = 0; i < 4 && clock.now_ns() < next_ns; ++i) {
      wait(UsbTimeout(std::max<std::int64_t>((next_ns - clock.now_ns() + 999'999) / 1'000'000, 1)));
    }
  }
  // Cycles (feeding the watchdog) until the controller is idle again: the cycles run, -1 on FAULT.
  int run_until_idle(int max) {
    for (int i = 0; i < max; ++i) {
      cycle(true);
      const ArmSnapshot s = controller->snapshot();
      if (s.fault) return -1;
      if (i > 1 && s.control == ControlState::IDLE) return i + 1;
    }
    return max;
  }
};

TEST(SimLibusbJaco, TheLoaderBindsLibusbToTheShim) {
  void* symbol = ::dlsym(RTLD_DEFAULT, "libusb_interrupt_transfer");
  ASSERT_NE(symbol, nullptr);
  Dl_info info{};
  ASSERT_NE(::dladdr(symbol, &info), 0);
  const std::string file = info.dli_fname;
  EXPECT_EQ(file.rfind(SIM_LIBUSB_DIR, 0), 0U)
      << "libusb comes from " << file << ": run this test through CTest (LD_LIBRARY_PATH)";
}

TEST(SimLibusbJaco, ParsesArmsAndPlacesThemBesideTheKinects) {
  for (const char* none : {"", "0", "  "}) {
    auto r = sim_libusb::parse_jacos(none);
    ASSERT_TRUE(r.has_value()) << none;
    EXPECT_TRUE(r->empty()) << none;
  }
  auto one = sim_libusb::parse_jacos("1");
  ASSERT_TRUE(one.has_value());
  ASSERT_EQ(one->size(), 1U);
  EXPECT_EQ(one->at(0).model, Model::JACO2);
  EXPECT_EQ(one->at(0).serial, SimJacoConfig{}.serial);
  EXPECT_EQ(one->at(0).start_state, ArmState::NOINIT);
  EXPECT_EQ(one->at(0).port, 1);
  // Beside the default Kinect (its hub on root port 1) the arm takes port 2.
  auto kinects = sim_libusb::parse_kinects("");
  ASSERT_TRUE(kinects.has_value());
  auto beside = sim_libusb::parse_jacos("1", *kinects);
  ASSERT_TRUE(beside.has_value());
  EXPECT_EQ(beside->at(0).port, 2);
  EXPECT_TRUE(sim_libusb::parse_kinects("none").value().empty());

  auto two = sim_libusb::parse_jacos(
      "state=ready, serial=LEFT01, name=left, fault_seed=9, model=v1; "
      "port=1,stale=2,usb_serial=R1");
  ASSERT_TRUE(two.has_value()) << two.error();
  ASSERT_EQ(two->size(), 2U);
  const SimJacoConfig& left = two->at(0);
  EXPECT_EQ(left.model, Model::JACO_V1);  // model= applies first, wherever it stands
  EXPECT_EQ(left.dsp.major, 4);
  EXPECT_EQ(left.start_state, ArmState::READY_STANDBY);
  EXPECT_EQ(left.serial, "LEFT01");
  EXPECT_EQ(left.client_name, "left");
  EXPECT_EQ(left.fault_seed, 9U);
  EXPECT_EQ(left.port, 2);  // arm 1 asked for port 1
  const SimJacoConfig& right = two->at(1);
  EXPECT_EQ(right.port, 1);
  EXPECT_EQ(right.faults.stale_replies, 2U);
  EXPECT_EQ(right.usb_serial, "R1");
  EXPECT_EQ(right.client_name, "sim-jaco-1");
  EXPECT_EQ(right.serial, "PJ00650019161751");

  for (const char* bad : {"model=jaco3", "state=home", "colour=red", "stale=x", "port=16",
                          "drop_out=2", "serial=01234567890123456789", "1;port=1,port=1;port=1"}) {
    EXPECT_FALSE(sim_libusb::parse_jacos(bad).has_value()) << bad;
  }
  EXPECT_FALSE(sim_libusb::parse_jacos("port=1", *kinects).has_value());  // the Kinect's hub
}

TEST(SimLibusbJaco, EnumeratesAFullSpeedArmWithTwoInterruptEndpoints) {
  SimBus bus("none", "1");
  libusb_context* ctx = nullptr;
  ASSERT_EQ(libusb_init(&ctx), LIBUSB_SUCCESS);
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx, &list);
  ASSERT_EQ(n, 2);  // the root hub and the arm
  libusb_device* arm = nullptr;
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device_descriptor d{};
    ASSERT_EQ(libusb_get_device_descriptor(list[i], &d), LIBUSB_SUCCESS);
    if (d.idVendor == VENDOR_KINOVA) arm = list[i];
  }
  ASSERT_NE(arm, nullptr);
  libusb_device_descriptor d{};
  ASSERT_EQ(libusb_get_device_descriptor(arm, &d), LIBUSB_SUCCESS);
  EXPECT_EQ(d.idProduct, PID_JACO);
  EXPECT_EQ(d.bDeviceClass, 0);
  EXPECT_EQ(d.iSerialNumber, 0);  // none by default
  EXPECT_EQ(libusb_get_device_speed(arm), LIBUSB_SPEED_FULL);
  EXPECT_EQ(libusb_get_bus_number(arm), 1);
  EXPECT_EQ(libusb_get_device_address(arm), 2);
  std::array<std::uint8_t, 7> ports{};
  ASSERT_EQ(libusb_get_port_numbers(arm, ports.data(), static_cast<int>(ports.size())), 1);
  EXPECT_EQ(ports[0], 1);
  ASSERT_NE(libusb_get_parent(arm), nullptr);
  libusb_config_descriptor* config = nullptr;
  ASSERT_EQ(libusb_get_active_config_descriptor(arm, &config), LIBUSB_SUCCESS);
  ASSERT_EQ(config->bNumInterfaces, 1);
  ASSERT_EQ(config->interface[0].num_altsetting, 1);
  const libusb_interface_descriptor& alt = config->interface[0].altsetting[0];
  EXPECT_EQ(alt.bInterfaceNumber, INTERFACE);
  ASSERT_EQ(alt.bNumEndpoints, 2);
  for (int e = 0; e < 2; ++e) {
    EXPECT_EQ(alt.endpoint[e].bEndpointAddress, e == 0 ? EP_OUT : EP_IN);
    EXPECT_EQ(alt.endpoint[e].bmAttributes & 3, LIBUSB_TRANSFER_TYPE_INTERRUPT);
    EXPECT_EQ(alt.endpoint[e].wMaxPacketSize, PACKET_BYTES);
  }
  libusb_free_config_descriptor(config);
  EXPECT_EQ(libusb_get_max_packet_size(arm, EP_IN), 64);
  libusb_device_handle* h = nullptr;
  libusb_device_handle* other = nullptr;
  ASSERT_EQ(libusb_open(arm, &h), LIBUSB_SUCCESS);
  ASSERT_EQ(libusb_open(arm, &other), LIBUSB_SUCCESS);
  std::array<unsigned char, 64> text{};
  const int length = static_cast<int>(text.size());
  ASSERT_GT(libusb_get_string_descriptor_ascii(h, d.iManufacturer, text.data(), length), 0);
  EXPECT_STREQ(reinterpret_cast<const char*>(text.data()), "Kinova inc.");
  ASSERT_GT(libusb_get_string_descriptor_ascii(h, d.iProduct, text.data(), length), 0);
  EXPECT_STREQ(reinterpret_cast<const char*>(text.data()), "Kinova Robotic Platform");
  EXPECT_EQ(libusb_kernel_driver_active(h, 0), 0);
  EXPECT_EQ(libusb_claim_interface(h, 0), LIBUSB_SUCCESS);
  EXPECT_EQ(libusb_claim_interface(other, 0), LIBUSB_ERROR_BUSY);  // one claim per arm
  libusb_close(h);
  EXPECT_EQ(libusb_claim_interface(other, 0), LIBUSB_SUCCESS);  // closing released it
  libusb_close(other);
  libusb_free_device_list(list, 1);
  libusb_exit(ctx);

  // The same arm as the driver's transport lists it.
  auto usb = LibusbTransport::create();
  ASSERT_TRUE(usb.has_value());
  auto arms = list_arms(**usb);
  ASSERT_TRUE(arms.has_value());
  ASSERT_EQ(arms->size(), 1U);
  EXPECT_EQ(arms->at(0).interface_count, 1);
  EXPECT_EQ(arms->at(0).port_depth, 1);
  EXPECT_TRUE(arms->at(0).serial.view().empty());
  auto cameras = kinect::list_cameras(**usb);
  ASSERT_TRUE(cameras.has_value());
  EXPECT_TRUE(cameras->empty());  // ORTHOFLOW_SIM_KINECT=none
}

TEST(SimLibusbJaco, RawExchangesTakeAMillisecondPerTransferAndTimeOutWithoutAReply) {
  SimBus bus("none", "1");
  libusb_context* ctx = nullptr;
  ASSERT_EQ(libusb_init(&ctx), LIBUSB_SUCCESS);
  libusb_device_handle* h = libusb_open_device_with_vid_pid(ctx, VENDOR_KINOVA, PID_JACO);
  ASSERT_NE(h, nullptr);
  Packet out = make_request(Command::GET_FIRMWARE);
  Packet in{};
  auto* out_bytes = reinterpret_cast<unsigned char*>(out.data());
  auto* in_bytes = reinterpret_cast<unsigned char*>(in.data());
  int moved = -1;
  EXPECT_EQ(libusb_interrupt_transfer(h, EP_IN, in_bytes, 64, &moved, 10), LIBUSB_ERROR_NOT_FOUND)
      << "no transfer before the claim";
  ASSERT_EQ(libusb_claim_interface(h, 0), LIBUSB_SUCCESS);
  EXPECT_EQ(libusb_interrupt_transfer(h, 0x81, in_bytes, 64, &moved, 10), LIBUSB_ERROR_NOT_FOUND);
  EXPECT_EQ(libusb_interrupt_transfer(h, EP_OUT, out_bytes, 63, &moved, 10),
            LIBUSB_ERROR_INVALID_PARAM);  // whole packets only
  std::array<unsigned char, 1> setup_data{};
  EXPECT_EQ(libusb_control_transfer(h, 0xC0, 1, 0, 0, setup_data.data(), 1, 10),
            LIBUSB_ERROR_PIPE);  // no vendor requests on EP0

  // Nothing pending: the IN waits its whole timeout (on the wall clock: the arm is real time).
  auto t0 = Clock::now();
  EXPECT_EQ(libusb_interrupt_transfer(h, EP_IN, in_bytes, 64, &moved, 30), LIBUSB_ERROR_TIMEOUT);
  EXPECT_GE(Clock::now() - t0, 30ms);

  t0 = Clock::now();
  constexpr int EXCHANGES = 20;
  for (int i = 0; i < EXCHANGES; ++i) {
    ASSERT_EQ(libusb_interrupt_transfer(h, EP_OUT, out_bytes, 64, &moved, 100), LIBUSB_SUCCESS);
    EXPECT_EQ(moved, 64);
    // Bulk on an interrupt endpoint runs as interrupt, as usbfs does.
    const int r = i % 2 == 0 ? libusb_interrupt_transfer(h, EP_IN, in_bytes, 64, &moved, 100)
                             : libusb_bulk_transfer(h, EP_IN, in_bytes, 64, &moved, 100);
    ASSERT_EQ(r, LIBUSB_SUCCESS);
    ASSERT_EQ(moved, 64);
    ASSERT_EQ(check_reply(in, Command::GET_FIRMWARE), PacketCheck::OK);
  }
  EXPECT_GE(Clock::now() - t0, std::chrono::milliseconds(2 * EXCHANGES));
  Firmware firmware;
  ASSERT_EQ(parse_firmware(in, firmware), PacketCheck::OK);
  EXPECT_EQ(firmware.dsp.major, 5);
  EXPECT_EQ(firmware.dsp.minor, 2);

  // A short IN buffer overflows; the reply is gone afterwards.
  ASSERT_EQ(libusb_interrupt_transfer(h, EP_OUT, out_bytes, 64, &moved, 100), LIBUSB_SUCCESS);
  EXPECT_EQ(libusb_interrupt_transfer(h, EP_IN, in_bytes, 32, &moved, 100), LIBUSB_ERROR_OVERFLOW);
  EXPECT_EQ(libusb_interrupt_transfer(h, EP_IN, in_bytes, 64, &moved, 5), LIBUSB_ERROR_TIMEOUT);
  // A port reset drops a pending reply.
  ASSERT_EQ(libusb_interrupt_transfer(h, EP_OUT, out_bytes, 64, &moved, 100), LIBUSB_SUCCESS);
  ASSERT_EQ(libusb_reset_device(h), LIBUSB_SUCCESS);
  EXPECT_EQ(libusb_interrupt_transfer(h, EP_IN, in_bytes, 64, &moved, 5), LIBUSB_ERROR_TIMEOUT);
  libusb_close(h);
  libusb_exit(ctx);
}

TEST(SimLibusbJaco, ControllerReadsTheIdentityMovesTheJointsAndLatchesTheEstop) {
  SimBus bus("none", "state=ready");
  Rig rig;
  ASSERT_NO_FATAL_FAILURE(rig.open());
  const SimJacoConfig config;  // what the arm was built from
  const ArmIdentity& id = rig.controller->identity();
  EXPECT_EQ(id.model, Model::JACO2);
  EXPECT_EQ(id.client.model.view(), config.model_string);
  EXPECT_EQ(id.client.serial.view(), config.serial);
  EXPECT_EQ(id.client.name.view(), config.client_name);
  EXPECT_EQ(id.client.organisation.view(), config.organisation);
  EXPECT_EQ(id.firmware.dsp.major, 5);
  EXPECT_EQ(id.device.vendor, VENDOR_KINOVA);
  ArmSnapshot s = rig.controller->snapshot();
  EXPECT_EQ(s.arm_state, ArmState::READY_STANDBY);
  EXPECT_LT(max_error(s.joints, config.home_joints), 1e-3);

  const JointAngles goal = offset(config.home_joints, {5.0, -4.0, 3.0, 6.0, -5.0, 8.0});
  ASSERT_TRUE(rig.controller->submit(move_to(goal)).has_value());
  const int cycles = rig.run_until_idle(1000);
  s = rig.controller->snapshot();
  EXPECT_EQ(s.last_stop, StopReason::REACHED) << to_string(s.last_stop) << " after " << cycles;
  EXPECT_LT(max_error(s.joints, goal), 0.3);
  EXPECT_GT(s.points_sent, 10U);
  for (int i = 0; i < 10; ++i) rig.cycle(true);  // it stays there
  s = rig.controller->snapshot();
  EXPECT_LT(max_error(s.joints, goal), 0.3);
  for (double v : s.velocity) EXPECT_LT(std::abs(v), 0.5);
  const LinkStats& link = rig.controller->link_stats();
  EXPECT_EQ(link.timeouts, 0U);
  EXPECT_EQ(link.bad_replies, 0U);
  EXPECT_EQ(link.retries, 0U);

  // The emergency stop mid-move: the arm stops and stays stopped until the latch is reset.
  ASSERT_TRUE(rig.controller->submit(move_to(config.home_joints)).has_value());
  for (int i = 0; i < 30; ++i) rig.cycle(true);  // ramping up at 40 deg/s^2, after the latency
  ASSERT_EQ(rig.controller->snapshot().control, ControlState::MOVING);
  ASSERT_GT(max_error(rig.controller->snapshot().joints, goal), 0.3);
  rig.controller->estop();
  rig.cycle(true);
  rig.cycle(true);
  s = rig.controller->snapshot();
  EXPECT_TRUE(s.estop);
  EXPECT_EQ(s.control, ControlState::ESTOP);
  EXPECT_EQ(s.last_stop, StopReason::ESTOP);
  for (int i = 0; i < 50; ++i) rig.cycle(true);  // the arm brakes to rest (its deceleration)
  const JointAngles stopped = rig.controller->snapshot().joints;
  for (int i = 0; i < 10; ++i) rig.cycle(true);
  EXPECT_LT(max_error(rig.controller->snapshot().joints, stopped), 0.01);
  auto refused = rig.controller->submit(move_to(config.home_joints));
  ASSERT_FALSE(refused.has_value());
  EXPECT_EQ(refused.error().code, JacoError::Code::ESTOP);
  ASSERT_TRUE(rig.controller->reset_estop().has_value());
  rig.cycle(true);
  EXPECT_FALSE(rig.controller->snapshot().estop);
  ASSERT_TRUE(rig.controller->submit(move_to(config.home_joints)).has_value());
  rig.run_until_idle(1000);
  s = rig.controller->snapshot();
  EXPECT_EQ(s.last_stop, StopReason::REACHED);
  EXPECT_LT(max_error(s.joints, config.home_joints), 0.3);
}

TEST(SimLibusbJaco, HomesFromNoinitOnBothModels) {
  for (const bool v1 : {false, true}) {
    SCOPED_TRACE(v1 ? "JACO v1, DSP 4 (state by command 200)" : "JACO2, DSP 5");
    SimBus bus("none", v1 ? "model=v1" : "1");
    Rig rig;
    ASSERT_NO_FATAL_FAILURE(rig.open());
    const SimJacoConfig config = v1 ? simulation::sim_jaco_v1_config() : SimJacoConfig{};
    EXPECT_EQ(rig.controller->identity().model, config.model);
    EXPECT_EQ(rig.controller->identity().firmware.dsp.dsp5(), !v1);
    EXPECT_EQ(rig.controller->snapshot().arm_state, ArmState::NOINIT);
    auto refused = rig.controller->submit(move_to(config.home_joints));
    ASSERT_FALSE(refused.has_value());
    EXPECT_EQ(refused.error().code, JacoError::Code::INVALID_STATE);
    ASSERT_TRUE(rig.controller->submit(ArmCommand{Kind::HOME}).has_value());
    const int cycles = rig.run_until_idle(3000);
    const ArmSnapshot s = rig.controller->snapshot();
    EXPECT_EQ(s.last_stop, StopReason::REACHED)
        << to_string(s.last_stop) << " after " << cycles << ": " << describe(s.violation);
    EXPECT_EQ(s.arm_state, ArmState::READY_STANDBY);
    EXPECT_LT(max_error(s.joints, config.home_joints), 0.3);
  }
}

TEST(SimLibusbJaco, StaleRepliesAreFlushedAtOpen) {
  SimBus bus("none", "state=ready,stale=3");
  Rig rig;
  ASSERT_NO_FATAL_FAILURE(rig.open());
  EXPECT_EQ(rig.controller->link_stats().flushed, 3U);
  EXPECT_EQ(rig.controller->link_stats().bad_replies, 0U);
}

// The production arm: JacoController on JacoArm's own USB thread, which owns the LibusbTransport.
TEST(SimLibusbJaco, JacoArmThreadMovesTheArm) {
  SimBus bus("none", "state=ready");
  auto usb = LibusbTransport::create();
  ASSERT_TRUE(usb.has_value());
  auto arms = list_arms(**usb);
  ASSERT_TRUE(arms.has_value());
  ASSERT_EQ(arms->size(), 1U);
  auto started = JacoArm::start(std::move(usb).value(), arms->front(), ArmOptions{});
  ASSERT_TRUE(started.has_value()) << to_string(started.error());
  JacoArm& arm = **started;
  const SimJacoConfig config;
  const JointAngles goal = offset(config.home_joints, {-6.0, 0.0, 4.0, 0.0, 0.0, -7.0});
  ASSERT_TRUE(arm.submit(move_to(goal)).has_value());
  const auto until = Clock::now() + 10s;
  ArmSnapshot s = arm.snapshot();
  while (Clock::now() < until) {
    arm.keep_alive();
    std::this_thread::sleep_for(20ms);
    s = arm.snapshot();
    if (s.cycle > 5 && s.control == ControlState::IDLE) break;
  }
  EXPECT_EQ(s.last_stop, StopReason::REACHED) << to_string(s.last_stop);
  EXPECT_LT(max_error(s.joints, goal), 0.3);
  EXPECT_FALSE(s.fault);
}

// One transport, one thread: the default Kinect streams depth while the arm moves, at the realtime
// pace (the arm keeps wall time in either pace; the Kinect's frames must keep it too).
TEST(SimLibusbJaco, TheArmMovesWhileAKinectStreamsOnTheSameBus) {
  SimBus bus("", "state=ready");
  ScopedEnv pace(sim_libusb::ENV_PACE, "realtime");
  Rig rig;
  auto usb_result = LibusbTransport::create();
  ASSERT_TRUE(usb_result.has_value());
  rig.usb = std::move(usb_result).value();
  auto cameras = kinect::list_cameras(*rig.usb);
  ASSERT_TRUE(cameras.has_value());
  ASSERT_EQ(cameras->size(), 1U);
  auto arms = list_arms(*rig.usb);
  ASSERT_TRUE(arms.has_value());
  ASSERT_EQ(arms->size(), 1U);
  EXPECT_EQ(arms->front().port_path[0], 2);  // beside the Kinect's hub on port 1
  auto camera_result = kinect::KinectCamera::open(*rig.usb, kinect::CameraOptions{});
  ASSERT_TRUE(camera_result.has_value()) << to_string(camera_result.error());
  kinect::KinectCamera& camera = **camera_result;
  ASSERT_TRUE(camera.start_depth().has_value());
  int frames = 0;
  rig.wait = [&](UsbTimeout t) {
    (void)camera.pump(t);
    if (camera.latest_depth() != nullptr) ++frames;
  };
  auto opened = JacoController::open(*rig.usb, arms->front());
  ASSERT_TRUE(opened.has_value()) << to_string(opened.error());
  rig.controller = std::move(opened).value();
  rig.next_ns = rig.usb->clock().now_ns();
  const SimJacoConfig config;
  const JointAngles goal = offset(config.home_joints, {8.0, 5.0, -5.0, 0.0, 6.0, 0.0});
  ASSERT_TRUE(rig.controller->submit(move_to(goal)).has_value());
  const auto t0 = Clock::now();
  rig.run_until_idle(1000);
  for (int i = 0; i < 20; ++i) rig.cycle(true);
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  const ArmSnapshot s = rig.controller->snapshot();
  EXPECT_EQ(s.last_stop, StopReason::REACHED) << to_string(s.last_stop);
  EXPECT_LT(max_error(s.joints, goal), 0.3);
  // 30 frames per simulated second, and simulated time kept up with the wall clock.
  EXPECT_GE(frames, static_cast<int>(30.0 * seconds * 0.5)) << seconds << " s";
  ASSERT_TRUE(camera.stop_depth().has_value());
  rig.controller.reset();
  camera_result->reset();
}

TEST(SimLibusbJaco, AMalformedDescriptionFailsLibusbInit) {
  for (const auto& [kinects, jacos] : {std::pair{"none", "model=jaco3"}, std::pair{"", "port=1"}}) {
    SimBus bus(kinects, jacos);
    auto usb = LibusbTransport::create();
    ASSERT_FALSE(usb.has_value()) << jacos;
    EXPECT_EQ(usb.error().code, UsbError::Code::INVALID_PARAM);
  }
}

}  // namespace
}  // namespace orthoflow::drivers::jaco
