// The isochronous frame assembler on synthetic packet streams (USB_TESTING.md 3.2): a known frame
// is split into 1748-byte (depth) or 1908-byte (video) payloads behind 12-byte headers, then fed
// clean, from mid-frame, with gaps, wraps, duplicates, reordering, corruption and bad sizes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include "drivers/kinect/kinect_assembler.hpp"

namespace orthoflow::drivers::kinect {
namespace {

using Packet = std::vector<std::uint8_t>;

/// Packets of one frame, starting at sequence @p seq, device time @p ticks on the last packet.
std::vector<Packet> packetize(const std::vector<std::uint8_t>& frame, const StreamGeometry& g,
                              std::uint8_t& seq, std::uint32_t ticks) {
  std::vector<Packet> out;
  for (std::size_t k = 0; k < g.packets; ++k) {
    const std::size_t n = k + 1 == g.packets ? g.last_payload : g.payload_bytes;
    Packet p(12 + n);
    p[0] = 0x52;
    p[1] = 0x42;
    p[3] = static_cast<std::uint8_t>(g.stream | (k == 0 ? 1 : k + 1 == g.packets ? 5 : 2));
    p[5] = seq++;
    p[6] = static_cast<std::uint8_t>(p.size() >> 8);
    p[7] = static_cast<std::uint8_t>(p.size() & 0xFF);
    const std::uint32_t t =
        k == 0 ? 0 : ticks - static_cast<std::uint32_t>(g.packets - 1 - k) * 7500;
    std::memcpy(p.data() + 8, &t, 4);
    std::memcpy(p.data() + 12, frame.data() + k * g.payload_bytes, n);
    out.push_back(std::move(p));
  }
  return out;
}

std::vector<std::uint8_t> random_frame(std::size_t bytes, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint8_t> f(bytes);
  for (auto& b : f) b = static_cast<std::uint8_t>(rng());
  return f;
}

struct Got {
  std::vector<std::uint8_t> bytes;
  std::vector<std::uint8_t> present;
  std::uint64_t ticks = 0;
  bool complete = false;
  std::size_t packets_present = 0;
};

struct Harness {
  explicit Harness(const StreamGeometry& g)
      : geometry(g), assembler(g, [this](const AssembledFrame& f) {
          frames.push_back({{f.bytes.begin(), f.bytes.end()},
                            {f.packet_present.begin(), f.packet_present.end()},
                            f.device_ticks,
                            f.complete,
                            f.packets_present});
        }) {}
  void feed(const std::vector<Packet>& packets) {
    for (const auto& p : packets) assembler.push(p, 0);
  }
  StreamGeometry geometry;
  std::vector<Got> frames;
  FrameAssembler assembler;
};

TEST(KinectGeometry, PacketCountsOfTheBrief) {
  const auto d11 = depth_geometry(11);
  EXPECT_EQ(d11.frame_bytes, 422400U);
  EXPECT_EQ(d11.packets, 242U);
  EXPECT_EQ(d11.last_payload, 1132U);
  const auto d10 = depth_geometry(10);
  EXPECT_EQ(d10.packets, 220U);
  EXPECT_EQ(d10.last_payload, 1188U);
  const auto bayer = video_geometry(640 * 480);
  EXPECT_EQ(bayer.packets, 162U);
  EXPECT_EQ(bayer.last_payload, 12U);
  EXPECT_EQ(video_geometry(640 * 488 * 10 / 8).packets, 205U);
}

TEST(KinectAssembler, CleanDepthAndBayerFramesArriveWhole) {
  for (const StreamGeometry g : {depth_geometry(11), video_geometry(640 * 480)}) {
    Harness h(g);
    std::uint8_t seq = 250;  // wraps inside the first frame
    const auto f1 = random_frame(g.frame_bytes, 1), f2 = random_frame(g.frame_bytes, 2);
    h.feed(packetize(f1, g, seq, 2'000'000));
    h.feed(packetize(f2, g, seq, 4'000'000));
    ASSERT_EQ(h.frames.size(), 2U);
    EXPECT_EQ(h.frames[0].bytes, f1);
    EXPECT_EQ(h.frames[1].bytes, f2);
    EXPECT_TRUE(h.frames[0].complete && h.frames[1].complete);
    EXPECT_EQ(h.frames[1].ticks - h.frames[0].ticks, 2'000'000U);
    EXPECT_EQ(h.assembler.stats().frames_complete, 2U);
    EXPECT_EQ(h.assembler.stats().lost_packets, 0U);
  }
}

TEST(KinectAssembler, StartingMidFrameDeliversNothingBeforeTheFirstStart) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  auto first = packetize(random_frame(g.frame_bytes, 3), g, seq, 100);
  const auto second_frame = random_frame(g.frame_bytes, 4);
  auto second = packetize(second_frame, g, seq, 200);
  h.feed(std::vector<Packet>(first.begin() + 100, first.end()));
  EXPECT_TRUE(h.frames.empty());
  EXPECT_EQ(h.assembler.stats().unsynced, 142U);
  h.feed(second);
  ASSERT_EQ(h.frames.size(), 1U);
  EXPECT_EQ(h.frames[0].bytes, second_frame);
}

TEST(KinectAssembler, LostPacketsBecomeMarkedHolesNeverStaleBytes) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  const auto f1 = random_frame(g.frame_bytes, 5), f2 = random_frame(g.frame_bytes, 6);
  h.feed(packetize(f1, g, seq, 1));
  auto p2 = packetize(f2, g, seq, 2);
  p2.erase(p2.begin() + 10, p2.begin() + 13);  // 3 lost in mid-frame
  h.feed(p2);
  ASSERT_EQ(h.frames.size(), 2U);
  const Got& got = h.frames[1];
  EXPECT_FALSE(got.complete);
  EXPECT_EQ(got.packets_present, 239U);
  EXPECT_EQ(h.assembler.stats().lost_packets, 3U);
  for (std::size_t k = 0; k < g.packets; ++k) {
    const bool hole = k >= 10 && k < 13;
    EXPECT_EQ(got.present[k], hole ? 0 : 1) << k;
    const auto* a = got.bytes.data() + k * g.payload_bytes;
    const std::size_t n = k + 1 == g.packets ? g.last_payload : g.payload_bytes;
    if (hole) {
      EXPECT_TRUE(std::all_of(a, a + n, [](std::uint8_t b) { return b == 0xFF; })) << k;
    } else {
      EXPECT_EQ(std::memcmp(a, f2.data() + k * g.payload_bytes, n), 0) << k;
    }
  }
  // Hole pixels: the three slots' bytes 17480..22724 in 11-bit pixels, rounded outwards.
  std::vector<PixelRange> ranges;
  AssembledFrame view;
  view.packet_present = got.present;
  for_each_hole_pixels(view, g, 11, 640 * 480, [&](PixelRange r) { ranges.push_back(r); });
  ASSERT_EQ(ranges.size(), 3U);
  EXPECT_EQ(ranges[0].begin, 10 * 1748 * 8 / 11);
  EXPECT_EQ(ranges[2].end, (13 * 1748 * 8 + 10) / 11);
}

TEST(KinectAssembler, GapAcrossTheEndOfAFrameDeliversItAndStartsTheNext) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  const auto f1 = random_frame(g.frame_bytes, 7), f2 = random_frame(g.frame_bytes, 8);
  auto p1 = packetize(f1, g, seq, 1);
  auto p2 = packetize(f2, g, seq, 2);
  std::vector<Packet> stream(p1.begin(), p1.end() - 2);   // last 2 of frame 1 lost
  stream.insert(stream.end(), p2.begin() + 1, p2.end());  // and the first of frame 2
  h.feed(stream);
  ASSERT_EQ(h.frames.size(), 2U);
  EXPECT_FALSE(h.frames[0].complete);
  EXPECT_EQ(h.frames[0].packets_present, 240U);
  EXPECT_FALSE(h.frames[1].complete);
  EXPECT_EQ(h.frames[1].packets_present, 241U);
  EXPECT_EQ(h.frames[1].present[0], 0);
  EXPECT_EQ(h.assembler.stats().lost_packets, 3U);
}

TEST(KinectAssembler, MoreThanFiveLostForcesAResync) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  const auto f1 = random_frame(g.frame_bytes, 9), f2 = random_frame(g.frame_bytes, 10);
  auto p1 = packetize(f1, g, seq, 1);
  p1.erase(p1.begin() + 50, p1.begin() + 56);  // 6 lost
  h.feed(p1);
  EXPECT_TRUE(h.frames.empty());
  EXPECT_EQ(h.assembler.stats().resyncs, 1U);
  EXPECT_EQ(h.assembler.stats().frames_abandoned, 1U);
  h.feed(packetize(f2, g, seq, 2));
  ASSERT_EQ(h.frames.size(), 1U);
  EXPECT_EQ(h.frames[0].bytes, f2);
}

TEST(KinectAssembler, DuplicatesDroppedAndSwappedPacketsRecovered) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  const auto f = random_frame(g.frame_bytes, 11);
  auto p = packetize(f, g, seq, 1);
  p.insert(p.begin() + 20, p[19]);  // a repeat
  std::swap(p[40], p[41]);          // adjacent packets reordered
  std::swap(p[100], p[102]);        // two apart
  h.feed(p);
  ASSERT_EQ(h.frames.size(), 1U);
  EXPECT_TRUE(h.frames[0].complete);
  EXPECT_EQ(h.frames[0].bytes, f);
  EXPECT_EQ(h.assembler.stats().duplicates, 1U);
  EXPECT_EQ(h.assembler.stats().late_packets, 3U);  // 41 before 40; 100 and 101 after 102
}

TEST(KinectAssembler, CorruptHeadersAreCountedAndNeverPlaced) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  const auto f = random_frame(g.frame_bytes, 12);
  auto p = packetize(f, g, seq, 1);
  p[5][0] = 0x00;                // bad magic
  p[6][3] = 0x82;                // another stream's flag
  p[8].resize(7);                // short header
  p[9].resize(p[9].size() + 4);  // oversize payload (size field fixed to match)
  p[9][6] = static_cast<std::uint8_t>(p[9].size() >> 8);
  p[9][7] = static_cast<std::uint8_t>(p[9].size() & 0xFF);
  p[10].resize(p[10].size() - 100);  // undersize (size field fixed)
  p[10][6] = static_cast<std::uint8_t>(p[10].size() >> 8);
  p[10][7] = static_cast<std::uint8_t>(p[10].size() & 0xFF);
  h.feed(p);
  h.assembler.push({}, 0);  // an idle microframe
  const auto& s = h.assembler.stats();
  EXPECT_EQ(s.bad_magic, 1U);
  EXPECT_EQ(s.wrong_stream, 1U);
  EXPECT_EQ(s.short_header, 1U);
  EXPECT_EQ(s.oversize, 1U);
  EXPECT_EQ(s.undersize, 1U);
  EXPECT_EQ(s.empty_packets, 1U);
  ASSERT_EQ(h.frames.size(), 1U);
  EXPECT_FALSE(h.frames[0].complete);
  for (std::size_t k : {5, 6, 8, 9, 10}) EXPECT_EQ(h.frames[0].present[k], 0) << k;
  EXPECT_EQ(h.frames[0].packets_present, 242U - 5U);
}

// Header bytes 6-7 read as a packet size are inferred (KINECT_V1.md 13, row 11) and libfreenect
// ignores them: packets whose field says anything else are placed as libfreenect places them, and
// counted.
TEST(KinectAssembler, ASizeFieldThatDisagreesIsCountedNotDropped) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  const auto f = random_frame(g.frame_bytes, 13);
  auto p = packetize(f, g, seq, 1);
  p[7][7] ^= 0x01;  // off by one
  p[8][6] = 0x00;   // zero
  p[8][7] = 0x00;
  p[241][6] = 0xFF;  // the last packet: far too large
  p[241][7] = 0xFF;
  h.feed(p);
  ASSERT_EQ(h.frames.size(), 1U);
  EXPECT_TRUE(h.frames[0].complete);
  EXPECT_EQ(h.frames[0].bytes, f);
  EXPECT_EQ(h.assembler.stats().bad_size_field, 3U);
}

TEST(KinectAssembler, WrongFlagAtAPositionResyncs) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  auto p = packetize(random_frame(g.frame_bytes, 13), g, seq, 1);
  p[30][3] = 0x75;  // EOF in mid-frame
  h.feed(p);
  EXPECT_TRUE(h.frames.empty());
  EXPECT_EQ(h.assembler.stats().flag_mismatches, 1U);
  const auto f = random_frame(g.frame_bytes, 14);
  h.feed(packetize(f, g, seq, 2));
  ASSERT_EQ(h.frames.size(), 1U);
  EXPECT_EQ(h.frames[0].bytes, f);
}

TEST(KinectAssembler, DeviceClockUnwrapsPast32Bits) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::uint8_t seq = 0;
  const auto f = random_frame(g.frame_bytes, 15);
  h.feed(packetize(f, g, seq, 0xFFFFFFFFU - 1'000'000U));
  h.feed(packetize(f, g, seq, 1'000'000U - 1U));  // wrapped
  ASSERT_EQ(h.frames.size(), 2U);
  EXPECT_EQ(h.frames[1].ticks - h.frames[0].ticks, 2'000'000U);
  EXPECT_GT(h.frames[1].ticks, 0xFFFFFFFFULL);
}

TEST(KinectAssembler, RandomFaultsNeverCrashAndAccountForEveryPacket) {
  const auto g = depth_geometry(11);
  Harness h(g);
  std::mt19937 rng(42);
  std::uint8_t seq = 0;
  std::uint64_t fed = 0;
  for (int frame = 0; frame < 30; ++frame) {
    auto p = packetize(random_frame(g.frame_bytes, 100 + frame), g, seq, 2'000'000U * frame);
    for (auto& packet : p) {
      const auto roll = static_cast<unsigned>(rng() % 1000);
      if (roll < 10) continue;  // 1 % lost
      if (roll < 15) packet[rng() % packet.size()] ^= static_cast<std::uint8_t>(1 + rng() % 255);
      h.assembler.push(packet, 0);
      ++fed;
      if (roll >= 15 && roll < 20) {
        h.assembler.push(packet, 0);  // duplicated
        ++fed;
      }
    }
  }
  const auto& s = h.assembler.stats();
  EXPECT_EQ(s.packets, fed);
  EXPECT_GE(h.frames.size(), 20U);
  EXPECT_EQ(s.frames_complete + s.frames_incomplete, h.frames.size());
  for (const Got& got : h.frames) EXPECT_EQ(got.bytes.size(), g.frame_bytes);
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
