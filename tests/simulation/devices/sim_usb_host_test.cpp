// SimUsbHost with different devices on one bus, as the robot has them: a Kinect and a JACO
// enumerate side by side at addresses of their own, depth streams while the arm answers, and
// unplugging one leaves the other alone. Also the one simulated camera of the CLI and the graph
// node (make_sim_kinect_host). Each device's own rules: sim_kinect_test.cpp, sim_jaco_test.cpp.
#include <memory>
#include <set>

#include "drivers/jaco/jaco_protocol.hpp"
#include "sim_kinect_test_support.hpp"
#include "simulation/devices/sim_jaco_usb_device.hpp"
#include "simulation/devices/sim_kinect_usb_device.hpp"
#include "simulation/devices/sim_usb_host.hpp"

namespace orthoflow::simulation::test {
namespace {

namespace jaco = drivers::jaco;
using Code = UsbError::Code;
using std::chrono::milliseconds;

constexpr std::size_t DEPTH_PACKETS = 242;  // per 11-bit frame

/// A host with a Kinect (device 0) and a JACO at HOME (device 1), both opened and claimed.
struct RobotBus {
  SimUsbHost host;
  SimKinectDevice* kinect = nullptr;
  SimJacoArm* arm = nullptr;
  UsbDeviceHandle cam;
  UsbDeviceHandle hand;
  std::uint16_t tag = 0;

  RobotBus() {
    auto k = std::make_unique<SimKinectUsbDevice>(cheap_config());
    kinect = &k->model();
    host.add_device(std::move(k));
    SimJacoConfig c;
    c.start_state = jaco::ArmState::READY_STANDBY;
    c.port = 2;
    auto a = std::make_unique<SimJacoUsbDevice>(c, host.clock().now_ns());
    arm = &a->arm();
    host.add_device(std::move(a));
    cam = open_one(KINECT_VENDOR, KINECT_CAMERA_PID);
    EXPECT_TRUE(host.detach_kernel_driver(cam, 0));
    EXPECT_TRUE(host.claim_interface(cam, 0));
    hand = open_one(jaco::VENDOR_KINOVA, jaco::PID_JACO);
    EXPECT_TRUE(host.claim_interface(hand, 0));
  }
  UsbDeviceHandle open_one(std::uint16_t vendor, std::uint16_t product) {
    auto list = host.enumerate(vendor, product);
    EXPECT_TRUE(list && list->size() == 1);
    auto h = host.open(list->front());
    EXPECT_TRUE(h);
    return std::move(*h);
  }
  void start_depth() {
    const std::pair<std::uint16_t, std::uint16_t> script[] = {
        {0x105, 0}, {0x06, 0}, {0x12, 3}, {0x13, 1}, {0x14, 0x1E}, {0x06, 2}, {0x17, 0}};
    for (const auto& [reg, value] : script) write_reg(host, cam, tag, reg, value);
  }
  /// One request / reply with the arm; the reply's command id, or an error.
  Result<std::uint16_t, UsbError> ask_arm(jaco::Command command) {
    jaco::Packet packet = jaco::make_request(command);
    auto sent = host.interrupt(hand, jaco::EP_OUT, packet, TIMEOUT_500MS);
    if (!sent) return orthoflow::err(sent.error());
    jaco::Packet reply{};
    auto got = host.interrupt(hand, jaco::EP_IN, reply, TIMEOUT_500MS);
    if (!got) return orthoflow::err(got.error());
    return jaco::read_header(reply).command_id;
  }
};

TEST(SimUsbHost, AKinectAndAnArmEnumerateOnOneBusAtAddressesOfTheirOwn) {
  RobotBus bus;
  const auto kinect = bus.host.enumerate(KINECT_VENDOR, std::nullopt);
  const auto arms = bus.host.enumerate(jaco::VENDOR_KINOVA, std::nullopt);
  ASSERT_TRUE(kinect && arms);
  ASSERT_EQ(kinect->size(), 3U);  // camera, motor, audio
  ASSERT_EQ(arms->size(), 1U);
  std::set<std::uint8_t> addresses;
  for (const UsbDeviceInfo& d : *kinect) addresses.insert(d.address);
  addresses.insert(arms->front().address);
  EXPECT_EQ(addresses.size(), 4U);
  // The Kinect's hub takes 2, its functions 3, 4, 5; the arm, added next, 6.
  EXPECT_EQ(*addresses.begin(), 3);
  EXPECT_EQ(arms->front().address, 6);
  EXPECT_EQ(arms->front().bus, kinect->front().bus);
  EXPECT_FALSE(drivers::same_parent_hub(arms->front(), kinect->front()));
  // Each keeps its own rules: the arm has no control endpoint, the camera no interrupt one.
  std::array<std::byte, 8> small{};
  EXPECT_EQ(bus.host.control(bus.hand, {0xC0, 0, 0, 0}, small, TIMEOUT_500MS).error().code,
            Code::NOT_SUPPORTED);
  EXPECT_EQ(bus.host.interrupt(bus.cam, 0x82, small, TIMEOUT_500MS).error().code, Code::NOT_FOUND);
  EXPECT_EQ(*bus.host.kernel_driver_active(bus.hand, 0), false);
}

TEST(SimUsbHost, DepthStreamsWhileTheArmAnswers) {
  RobotBus bus;
  Collector depth;
  ASSERT_TRUE(bus.host.start_iso(bus.cam, KINECT_DEPTH_ENDPOINT, {16, 16, 1920}, depth.callback()));
  bus.start_depth();
  const std::uint64_t cycles = bus.arm->counters().cycles;
  const std::int64_t t0 = bus.host.clock().now_ns();
  for (int i = 0; i < 150; ++i) {  // 2 ms each: the iso transfers complete inside the transfers
    const auto id = bus.ask_arm(jaco::Command::GET_ANG_POS);
    ASSERT_TRUE(id) << i;
    EXPECT_EQ(*id, static_cast<std::uint16_t>(jaco::Command::GET_ANG_POS));
  }
  const std::int64_t elapsed = bus.host.clock().now_ns() - t0;
  EXPECT_EQ(elapsed, 300'000'000);
  EXPECT_EQ(bus.arm->counters().cycles, cycles + 30);  // the 10 ms cycle ran all along
  const auto frames = frames_of(depth.packets);
  ASSERT_GE(frames.size(), 8U);  // 30 Hz over 0.3 s, the first and last partial
  std::vector<std::uint16_t> expected(PIXELS);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    ASSERT_EQ(frames[k].size(), DEPTH_PACKETS) << k;
    const std::vector<std::uint8_t> payload = payload_of(depth.packets, frames[k]);
    pattern_depth(k, expected);
    for (std::size_t i = 0; i < PIXELS; i += 997) ASSERT_EQ(read_bits(payload, i, 11), expected[i]);
  }
  EXPECT_EQ(bus.kinect->depth_counters().packets_dropped, 0U);
}

TEST(SimUsbHost, UnpluggingOneDeviceLeavesTheOtherAlone) {
  RobotBus bus;
  Collector depth;
  ASSERT_TRUE(bus.host.start_iso(bus.cam, KINECT_DEPTH_ENDPOINT, {8, 16, 1920}, depth.callback()));
  bus.start_depth();
  bus.host.run_for(milliseconds(50));
  bus.host.unplug_device(0);
  EXPECT_EQ(depth.packets.back().status, UsbPacketStatus::NO_DEVICE);
  EXPECT_TRUE(bus.host.enumerate(KINECT_VENDOR, std::nullopt)->empty());
  EXPECT_TRUE(bus.ask_arm(jaco::Command::GET_FIRMWARE));  // the arm answers on
  std::vector<std::uint8_t> reply;
  EXPECT_EQ(gm_read(bus.host, bus.cam, reply).error().code, Code::NO_DEVICE);
  // The arm's cable now; then both come back, the Kinect at addresses after the arm's.
  bus.host.unplug_device(1);
  EXPECT_EQ(bus.ask_arm(jaco::Command::GET_FIRMWARE).error().code, Code::NO_DEVICE);
  EXPECT_FALSE(bus.host.device_present(1));
  bus.host.replug_device(0);
  bus.host.replug_device(1);
  const auto cams = bus.host.enumerate(KINECT_VENDOR, KINECT_CAMERA_PID);
  const auto arms = bus.host.enumerate(jaco::VENDOR_KINOVA, std::nullopt);
  ASSERT_EQ(cams->size(), 1U);
  ASSERT_EQ(arms->size(), 1U);
  EXPECT_EQ(cams->front().address, 8);  // hub 7
  EXPECT_EQ(arms->front().address, 11);
  EXPECT_EQ(*bus.host.kernel_driver_active(bus.open_one(KINECT_VENDOR, KINECT_CAMERA_PID), 0),
            true);
}

TEST(SimUsbHost, TheArmsUnplugFaultDoesNotEndAWaitButTheKinectsDisconnectDoes) {
  // The JACO's unplug happens as time passes it (handle_events still waits its whole timeout);
  // the Kinect's disconnect is an event that ends the wait (as SimJacoTransport and
  // SimUsbTransport did).
  SimUsbHost host;
  SimJacoConfig c;
  c.faults.unplug_at_ns = 3'000'000;
  host.add_device(std::make_unique<SimJacoUsbDevice>(c, 0));
  ASSERT_TRUE(host.handle_events(milliseconds(10)));
  EXPECT_EQ(host.clock().now_ns(), 10'000'000);
  EXPECT_FALSE(host.device_present(0));
  SimKinectConfig k = cheap_config();
  k.faults.disconnect_at_ns = 14'000'000;
  host.add_device(std::make_unique<SimKinectUsbDevice>(k));
  ASSERT_TRUE(host.handle_events(milliseconds(10)));
  EXPECT_EQ(host.clock().now_ns(), 14'000'000);
  EXPECT_FALSE(host.device_present(1));
}

TEST(SimUsbHost, MakeSimKinectHostBuildsTheCameraTheCliAndTheGraphNodeRun) {
  SimKinectHostOptions options;
  options.model = KinectModel::K1473;
  options.scene_seed = 7;
  options.drop_rate = 0.25;
  options.serial = "B00367707040045B";
  const auto host = make_sim_kinect_host(options);
  ASSERT_EQ(host->kinect_count(), 1U);
  EXPECT_EQ(host->clock().now_ns(), 0);
  const SimKinectConfig& c = host->kinect(0).config();
  EXPECT_EQ(c.model, KinectModel::K1473);
  EXPECT_EQ(c.scene_seed, 7U);
  EXPECT_EQ(c.faults.packets.drop_rate, 0.25);
  EXPECT_EQ(c.serial, "B00367707040045B");
  EXPECT_EQ(host->enumerate(KINECT_VENDOR, KINECT_CAMERA_PID)->size(), 1U);
  EXPECT_EQ(make_sim_kinect_host()->kinect(0).config().serial, SimKinectConfig{}.serial);
}

}  // namespace
}  // namespace orthoflow::simulation::test
