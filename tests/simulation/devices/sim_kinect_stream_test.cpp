// The simulated Kinect's isochronous streams through SimUsbTransport: packet layout, timing,
// bit-exact depth, start/stop, small buffers and the default source. Bus faults, unplug/replug and
// unrequested cancels: sim_kinect_faults_test.cpp.
#include <algorithm>
#include <set>

#include "sim_kinect_test_support.hpp"

namespace orthoflow::simulation::test {
namespace {

using Code = UsbError::Code;
using std::chrono::milliseconds;

std::uint16_t be16(const std::vector<std::uint8_t>& b, std::size_t at) {
  return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
}
std::uint32_t le32(const std::vector<std::uint8_t>& b, std::size_t at) {
  return b[at] | (b[at + 1] << 8) | (b[at + 2] << 16) |
         (static_cast<std::uint32_t>(b[at + 3]) << 24);
}

TEST(SimKinectStream, PackerFollowsTheElevenBitTable) {
  // p0 = 0x7FF, p2 = 0x401 (b2[1:0] b3 b4[7]), the rest 0 (KINECT_V1.md 7.1).
  const std::uint16_t pixels[8] = {0x7FF, 0, 0x401, 0, 0, 0, 0, 0x003};
  std::uint8_t out[11] = {};
  EXPECT_EQ(sim_pack_msb_first(pixels, 11, out), 11U);
  const std::uint8_t expected[11] = {0xFF, 0xE0, 0x02, 0x00, 0x80, 0, 0, 0, 0, 0, 0x03};
  EXPECT_TRUE(std::equal(out, out + 11, expected));
  const std::uint16_t ten[4] = {0x3FF, 0, 0, 0x001};
  std::uint8_t out10[5] = {};
  EXPECT_EQ(sim_pack_msb_first(ten, 10, out10), 5U);
  const std::uint8_t expected10[5] = {0xFF, 0xC0, 0, 0, 0x01};
  EXPECT_TRUE(std::equal(out10, out10 + 5, expected10));
}

TEST(SimKinectStream, DepthScriptStreamsBitExactFramesOf242Packets) {
  Rig rig;
  Collector c;
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x82, {16, 16, 1920}, c.callback()));  // submit first
  rig.start_depth();
  EXPECT_EQ(rig.device().depth_mode(), SimStreamMode::DEPTH_11BIT);
  const std::vector<std::pair<std::uint16_t, std::uint16_t>> script = {
      {0x105, 0}, {0x06, 0}, {0x12, 3}, {0x13, 1}, {0x14, 0x1E}, {0x06, 2}, {0x17, 0}};
  EXPECT_EQ(rig.device().register_writes(), script);
  while (frames_of(c.packets).size() < 3) ASSERT_TRUE(rig.usb.handle_events(milliseconds(100)));
  const auto frames = frames_of(c.packets);
  EXPECT_EQ(frames_of(c.packets).front().front(), 0U);  // the first packet is an SOF
  std::vector<std::uint16_t> raw(PIXELS);
  for (std::size_t f = 0; f < 2; ++f) {
    const auto& frame = frames[f];
    ASSERT_EQ(frame.size(), 242U);
    for (std::size_t i = 0; i < frame.size(); ++i) {
      const auto& b = c.packets[frame[i]].bytes;
      ASSERT_EQ(b[0], 0x52);
      ASSERT_EQ(b[1], 0x42);
      ASSERT_EQ(b[2], 0x00);
      ASSERT_EQ(b[3], i == 0 ? 0x71 : (i == 241 ? 0x75 : 0x72));
      ASSERT_EQ(b[5], static_cast<std::uint8_t>(f * 242 + i));  // wraps 255 -> 0 in frame 1
      ASSERT_EQ(be16(b, 6), b.size());
      ASSERT_EQ(b.size() - 12, i == 241 ? 1132U : 1748U);
    }
    // Bit for bit: the naive reader over the reassembled payload gives the exposed raw image.
    const auto payload = payload_of(c.packets, frame);
    ASSERT_EQ(payload.size(), 422'400U);
    rig.device().depth_raw_image(f, raw);
    std::size_t mismatches = 0;
    for (std::size_t k = 0; k < PIXELS; ++k) mismatches += read_bits(payload, k, 11) != raw[k];
    EXPECT_EQ(mismatches, 0U) << "frame " << f;
  }
  const std::uint32_t t0 = le32(c.packets[frames[0].back()].bytes, 8);
  const std::uint32_t t1 = le32(c.packets[frames[1].back()].bytes, 8);
  const std::uint32_t t2 = le32(c.packets[frames[2].back()].bytes, 8);
  EXPECT_EQ(t1 - t0, 2'000'000U);
  EXPECT_EQ(t2 - t1, 2'000'000U);
  EXPECT_GT(c.empty, 0U);  // idle microframes are zero-length COMPLETED packets
}

TEST(SimKinectStream, ThirtyFramesPerSimulatedSecondUntilTheStopRegister) {
  Rig rig;
  Collector c;
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x82, {16, 16, 1920}, c.callback()));
  rig.start_depth();
  const std::int64_t t0 = rig.usb.clock().now_ns();
  while (rig.usb.clock().now_ns() - t0 < 1'000'000'000)
    ASSERT_TRUE(rig.usb.handle_events(milliseconds(50)));
  const auto sofs = std::count_if(c.packets.begin(), c.packets.end(),
                                  [](const Packet& p) { return p.bytes[3] == 0x71; });
  EXPECT_GE(sofs, 29);
  EXPECT_LE(sofs, 31);
  const drivers::UsbIsoStats stats = *rig.usb.iso_stats(rig.cam, 0x82);
  EXPECT_EQ(stats.packets_completed, stats.transfers_completed * 16);
  EXPECT_EQ(stats.packets_completed, c.packets.size() + c.empty);
  EXPECT_EQ(stats.transfers_in_flight, 16U);
  write_reg(rig.usb, rig.cam, rig.tag, 0x06, 0);
  rig.usb.run_for(milliseconds(5));  // what was sent before the write
  const std::size_t before = c.packets.size();
  rig.usb.run_for(milliseconds(200));
  EXPECT_EQ(c.packets.size(), before);
  EXPECT_EQ(rig.device().depth_mode(), SimStreamMode::OFF);
  // stop_iso: nothing is delivered afterwards.
  ASSERT_TRUE(rig.usb.stop_iso(rig.cam, 0x82));
  const std::size_t empties = c.empty;
  rig.usb.run_for(milliseconds(100));
  EXPECT_EQ(c.empty, empties);
}

TEST(SimKinectStream, TenBitDepthAndBayerRunTogether) {
  Rig rig;
  Collector depth;
  Collector video;
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x82, {}, depth.callback()));
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x81, {}, video.callback()));
  rig.start_depth(2);
  for (const auto& [reg, value] : {std::pair<std::uint16_t, std::uint16_t>{0x0C, 0},
                                   {0x0D, 1},
                                   {0x0E, 0x1E},
                                   {0x05, 1},
                                   {0x47, 0}})
    write_reg(rig.usb, rig.cam, rig.tag, reg, value);
  rig.usb.run_for(milliseconds(120));
  const auto d = frames_of(depth.packets);
  const auto v = frames_of(video.packets);
  ASSERT_GE(d.size(), 2U);
  ASSERT_GE(v.size(), 2U);
  ASSERT_EQ(d[0].size(), 220U);
  EXPECT_EQ(depth.packets[d[0].back()].bytes.size(), 12U + 1188U);
  ASSERT_EQ(v[0].size(), 162U);
  EXPECT_EQ(video.packets[v[0].front()].bytes[3], 0x81);
  EXPECT_EQ(video.packets[v[0][1]].bytes[3], 0x82);
  EXPECT_EQ(video.packets[v[0].back()].bytes[3], 0x85);
  EXPECT_EQ(video.packets[v[0].back()].bytes.size(), 24U);
  std::vector<std::uint8_t> bayer(PIXELS);
  rig.device().bayer_image(0, bayer);
  EXPECT_EQ(payload_of(video.packets, v[0]), bayer);
  std::vector<std::uint16_t> raw(PIXELS);
  rig.device().depth_raw_image(0, raw);
  const auto payload = payload_of(depth.packets, d[0]);
  std::size_t mismatches = 0;
  for (std::size_t k = 0; k < PIXELS; ++k)
    mismatches += read_bits(payload, k, 10) != std::min<std::uint16_t>(raw[k], 1023);
  EXPECT_EQ(mismatches, 0U);
}

TEST(SimKinectStream, IrModeSends640x488TenBitFramesOnTheVideoEndpoint) {
  Rig rig;
  Collector c;
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x81, {}, c.callback()));
  for (const auto& [reg, value] : {std::pair<std::uint16_t, std::uint16_t>{0x19, 0},
                                   {0x1A, 1},
                                   {0x1B, 0x1E},
                                   {0x105, 0},
                                   {0x05, 3},
                                   {0x48, 0}})
    write_reg(rig.usb, rig.cam, rig.tag, reg, value);
  EXPECT_EQ(rig.device().video_mode(), SimStreamMode::IR_10BIT);
  rig.usb.run_for(milliseconds(80));
  const auto frames = frames_of(c.packets);
  ASSERT_GE(frames.size(), 1U);
  ASSERT_EQ(frames[0].size(), 205U);
  EXPECT_EQ(c.packets[frames[0].back()].bytes.size(), 12U + 1168U);
  const auto payload = payload_of(c.packets, frames[0]);
  std::vector<std::uint16_t> ir(640 * 488);
  rig.device().ir_image(0, ir);
  std::size_t mismatches = 0;
  for (std::size_t k = 0; k < ir.size(); ++k) mismatches += read_bits(payload, k, 10) != ir[k];
  EXPECT_EQ(mismatches, 0U);
}

TEST(SimKinectStream, TwoKinectsStreamIndependently) {
  SimUsbTransport usb;
  SimKinectConfig second = cheap_config();
  second.hub_ports = {2};
  second.serial = "B00364A11700045B";
  usb.add_kinect(cheap_config());
  usb.add_kinect(second);
  auto cams = usb.enumerate(0x045E, 0x02AE);
  ASSERT_EQ(cams->size(), 2U);
  std::vector<UsbDeviceHandle> handles;
  std::vector<Collector> collectors(2);
  std::uint16_t tag = 0;
  for (std::size_t i = 0; i < 2; ++i) {
    handles.push_back(std::move(usb.open((*cams)[i])).value());
    ASSERT_TRUE(usb.detach_kernel_driver(handles[i], 0));
    ASSERT_TRUE(usb.claim_interface(handles[i], 0));
    ASSERT_TRUE(usb.start_iso(handles[i], 0x82, {}, collectors[i].callback()));
  }
  write_reg(usb, handles[0], tag, 0x12, 3);
  write_reg(usb, handles[0], tag, 0x06, 2);
  usb.run_for(milliseconds(70));
  EXPECT_GE(frames_of(collectors[0].packets).size(), 1U);
  EXPECT_TRUE(collectors[1].packets.empty());  // its depth register was never written
  EXPECT_GT(collectors[1].empty, 0U);
}

TEST(SimKinectStream, HandleEventsStopsAtTheNextCompletionOrTheTimeout) {
  Rig rig;
  const std::int64_t t0 = rig.usb.clock().now_ns();
  ASSERT_TRUE(rig.usb.handle_events(milliseconds(10)));  // nothing in flight: the whole timeout
  EXPECT_EQ(rig.usb.clock().now_ns() - t0, 10'000'000);
  Collector c;
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x82, {4, 8, 1920}, c.callback()));
  ASSERT_TRUE(rig.usb.handle_events(milliseconds(0)));
  EXPECT_EQ(c.empty, 0U);
  const std::int64_t t1 = rig.usb.clock().now_ns();
  ASSERT_TRUE(rig.usb.handle_events(milliseconds(1000)));  // one transfer: 8 x 125 us
  EXPECT_EQ(rig.usb.clock().now_ns() - t1, 1'000'000);
  EXPECT_EQ(c.empty, 8U);
  rig.usb.manual_clock().advance(milliseconds(2));  // moved by hand: 2 more transfers are due
  ASSERT_TRUE(rig.usb.handle_events(milliseconds(0)));
  EXPECT_EQ(c.empty, 24U);
}

TEST(SimKinectStream, SmallPacketBuffersOverflow) {
  Rig rig;
  Collector c;
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x82, {16, 16, 1024}, c.callback()));
  rig.start_depth();
  rig.usb.run_for(milliseconds(40));
  ASSERT_FALSE(c.packets.empty());
  EXPECT_TRUE(std::all_of(c.packets.begin(), c.packets.end(), [](const Packet& p) {
    return p.status == UsbPacketStatus::OVERFLOW && p.bytes.empty();
  }));
  EXPECT_EQ(rig.usb.iso_stats(rig.cam, 0x82)->packets_failed, c.packets.size());
}

TEST(SimKinectStream, DefaultSourceIsTheRenderedTabletop) {
  SimKinectConfig config;  // no sources: the synthetic scene
  Rig rig(config);
  std::vector<std::uint16_t> raw(PIXELS);
  std::vector<std::uint16_t> later(PIXELS);
  rig.device().depth_raw_image(0, raw);
  rig.device().depth_raw_image(5, later);
  EXPECT_EQ(raw, later);  // rendered once, reused
  const auto valid =
      std::count_if(raw.begin(), raw.end(), [](std::uint16_t v) { return v < 2047; });
  EXPECT_GT(valid, static_cast<long>(PIXELS / 2));
  EXPECT_LT(valid, static_cast<long>(PIXELS));  // shadows and dropouts read 2047
  EXPECT_TRUE(std::all_of(raw.begin(), raw.end(), [](std::uint16_t v) { return v <= 2047; }));
}

}  // namespace
}  // namespace orthoflow::simulation::test
