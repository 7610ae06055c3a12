// ForwardingTransport: every call reaches the inner transport with the handle mapped, the inner
// transport's rules (and errors) come through unchanged, and the hook sees each call before and
// after, with its arguments and outcome.
#include <algorithm>
#include <array>
#include <optional>
#include <utility>
#include <vector>

#include "drivers/jaco/jaco_protocol.hpp"
#include "sim_kinect_test_support.hpp"
#include "simulation/devices/forwarding_transport.hpp"
#include "simulation/devices/sim_jaco_transport.hpp"

namespace orthoflow::simulation::test {
namespace {

namespace jaco = drivers::jaco;
using Code = UsbError::Code;

/// Keeps every call the hook saw.
class Tap final : public ForwardingTransport {
 public:
  using ForwardingTransport::ForwardingTransport;
  struct Seen {
    SeamOp op;
    bool done;
    std::uint32_t handle;
    std::uint8_t number;
    std::optional<Code> error;
    std::size_t bytes;
    std::vector<std::byte> data;
  };
  mutable std::vector<Seen> seen;
  [[nodiscard]] std::size_t count(SeamOp op) const {
    return static_cast<std::size_t>(std::count_if(
        seen.begin(), seen.end(), [&](const Seen& s) { return s.op == op && s.done; }));
  }

 protected:
  void on_call(const SeamCall& call) const override {
    std::optional<Code> code;
    if (call.error) code = call.error->code;
    seen.push_back({call.op, call.done, call.handle, call.number, code, call.bytes,
                    std::vector<std::byte>(call.data.begin(), call.data.end())});
  }
};

SimJacoConfig ready() {
  SimJacoConfig c;
  c.start_state = jaco::ArmState::READY_STANDBY;
  return c;
}

TEST(ForwardingTransport, HandlesAreItsOwnAndTheInnerRulesComeThrough) {
  SimJacoTransport sim;
  sim.add_arm(ready());
  Tap tap(sim);
  EXPECT_EQ(&tap.clock(), &sim.clock());
  const auto list = tap.enumerate(jaco::VENDOR_KINOVA, std::nullopt);
  ASSERT_TRUE(list && list->size() == 1);
  auto first = tap.open(list->front());
  auto second = tap.open(list->front());
  ASSERT_TRUE(first && second);
  EXPECT_EQ(first->transport(), &tap);
  EXPECT_EQ(first->id(), 1U);
  EXPECT_EQ(second->id(), 2U);
  EXPECT_EQ(tap.claim_interface(UsbDeviceHandle{}, 0).error().code, Code::NOT_OPEN);
  EXPECT_EQ(sim.claim_interface(*first, 0).error().code, Code::NOT_OPEN);  // not the sim's handle
  ASSERT_TRUE(tap.claim_interface(*first, 0));
  EXPECT_EQ(tap.claim_interface(*second, 0).error().code, Code::BUSY);
  EXPECT_EQ(tap.start_iso(*first, 0x82, {}, [](auto, auto, auto) {}).error().code, Code::NOT_FOUND);
  // Closing a handle closes the inner one (its claim goes); ids are never reused.
  tap.close(*first);
  EXPECT_EQ(tap.claim_interface(*first, 0).error().code, Code::NOT_OPEN);
  EXPECT_TRUE(tap.claim_interface(*second, 0));
  auto third = tap.open(list->front());
  ASSERT_TRUE(third);
  EXPECT_EQ(third->id(), 3U);
  EXPECT_EQ(tap.count(SeamOp::CLOSE), 1U);
}

TEST(ForwardingTransport, TheHookSeesEachCallBeforeAndAfter) {
  SimJacoTransport sim;
  sim.add_arm(ready());
  Tap tap(sim);
  auto h = tap.open(tap.enumerate(jaco::VENDOR_KINOVA, std::nullopt)->front());
  ASSERT_TRUE(h && tap.claim_interface(*h, 0));
  tap.seen.clear();
  jaco::Packet out = jaco::make_request(jaco::Command::GET_FIRMWARE);
  ASSERT_TRUE(tap.interrupt(*h, jaco::EP_OUT, out, UsbTimeout{100}));
  jaco::Packet in{};
  ASSERT_EQ(*tap.interrupt(*h, jaco::EP_IN, in, UsbTimeout{100}), 64U);
  EXPECT_EQ(tap.interrupt(*h, jaco::EP_IN, in, UsbTimeout{5}).error().code, Code::TIMEOUT);
  ASSERT_EQ(tap.seen.size(), 6U);
  const Tap::Seen& before = tap.seen[0];
  EXPECT_EQ(before.op, SeamOp::INTERRUPT);
  EXPECT_FALSE(before.done);
  EXPECT_EQ(before.handle, h->id());
  EXPECT_EQ(before.number, jaco::EP_OUT);
  EXPECT_EQ(before.data, std::vector<std::byte>(out.begin(), out.end()));
  EXPECT_TRUE(tap.seen[1].done);
  EXPECT_EQ(tap.seen[1].bytes, 64U);
  EXPECT_FALSE(tap.seen[1].error);
  EXPECT_EQ(tap.seen[3].data, std::vector<std::byte>(in.begin(), in.end()));  // IN bytes, after
  EXPECT_EQ(jaco::read_header(in).command_id,
            static_cast<std::uint16_t>(jaco::Command::GET_FIRMWARE));
  EXPECT_EQ(tap.seen[5].error, Code::TIMEOUT);
  EXPECT_STREQ(to_string(SeamOp::INTERRUPT), "interrupt");
  EXPECT_STREQ(to_string(SeamOp::HANDLE_EVENTS), "handle_events");
}

TEST(ForwardingTransport, IsoStreamsRunThroughIt) {
  SimUsbTransport sim;
  sim.add_kinect(cheap_config());
  Tap tap(sim);
  auto cam = tap.open(tap.enumerate(KINECT_VENDOR, KINECT_CAMERA_PID)->front());
  ASSERT_TRUE(cam);
  EXPECT_TRUE(*tap.kernel_driver_active(*cam, 0));
  ASSERT_TRUE(tap.detach_kernel_driver(*cam, 0));
  ASSERT_TRUE(tap.claim_interface(*cam, 0));
  EXPECT_EQ(*tap.max_iso_packet_size(*cam, KINECT_DEPTH_ENDPOINT), 1920U);
  Collector c;
  ASSERT_TRUE(tap.start_iso(*cam, KINECT_DEPTH_ENDPOINT, {4, 8, 1920}, c.callback()));
  ASSERT_TRUE(tap.handle_events(std::chrono::milliseconds(10)));
  EXPECT_EQ(c.empty, 8U);  // one transfer of idle microframes
  EXPECT_EQ(tap.iso_stats(*cam, KINECT_DEPTH_ENDPOINT)->transfers_completed, 1U);
  EXPECT_EQ(tap.count(SeamOp::ISO_STATS), 1U);
  ASSERT_TRUE(tap.stop_iso(*cam, KINECT_DEPTH_ENDPOINT));
  // Closing re-attaches the kernel driver it detached, through the inner transport.
  tap.close(*cam);
  auto again = sim.open(sim.enumerate(KINECT_VENDOR, KINECT_CAMERA_PID)->front());
  EXPECT_TRUE(*sim.kernel_driver_active(*again, 0));
}

TEST(ForwardingTransport, EveryCallReachesTheInnerTransportAndTheHook) {
  SimUsbTransport sim;
  SimKinectConfig config = cheap_config();
  config.audio_firmware_running = true;
  sim.add_kinect(config);
  Tap tap(sim);
  auto audio = tap.open(tap.enumerate(KINECT_VENDOR, KINECT_AUDIO_PID)->front());
  ASSERT_TRUE(audio);
  ASSERT_TRUE(tap.claim_interface(*audio, 0));
  EXPECT_TRUE(tap.set_alt_setting(*audio, 0, 0));
  EXPECT_EQ(tap.attach_kernel_driver(*audio, 0).error().code, Code::NOT_FOUND);
  EXPECT_TRUE(tap.clear_halt(*audio, 0x81));
  EXPECT_TRUE(tap.reset_device(*audio));
  std::array<std::byte, 8> setup_data{};
  EXPECT_EQ(tap.control(*audio, {0xC0, 0, 0, 0}, setup_data, UsbTimeout{100}).error().code,
            Code::PIPE);  // the audio function answers no control requests
  std::array<std::byte, 12> status{};
  EXPECT_EQ(tap.bulk(*audio, 0x81, status, UsbTimeout{100}).error().code, Code::TIMEOUT);
  EXPECT_TRUE(tap.release_interface(*audio, 0));
  const SeamOp ops[] = {SeamOp::ENUMERATE,        SeamOp::OPEN,       SeamOp::CLAIM_INTERFACE,
                        SeamOp::SET_ALT_SETTING,  SeamOp::CLEAR_HALT, SeamOp::ATTACH_KERNEL_DRIVER,
                        SeamOp::RESET_DEVICE,     SeamOp::CONTROL,    SeamOp::BULK,
                        SeamOp::RELEASE_INTERFACE};
  for (const SeamOp op : ops) EXPECT_EQ(tap.count(op), 1U) << to_string(op);
  EXPECT_EQ(tap.seen.size(), 2 * std::size(ops));         // each before and after
  EXPECT_EQ(sim.clock().now_ns(), 50'000 + 100'000'000);  // one control latency, one bulk timeout
}

}  // namespace
}  // namespace orthoflow::simulation::test
