// The simulated Kinect's faults through SimUsbTransport: seeded bus faults on the iso packets
// (drop, duplicate, reorder, corrupt), unplug/replug and unrequested cancels.
#include <algorithm>
#include <set>

#include "sim_kinect_test_support.hpp"

namespace orthoflow::simulation::test {
namespace {

using Code = UsbError::Code;
using std::chrono::milliseconds;

/// One second of depth packets under @p faults.
std::vector<Packet> one_second(const SimPacketFaults& faults, std::uint64_t seed,
                               SimStreamCounters* counters = nullptr) {
  SimKinectConfig config = cheap_config();
  config.fault_seed = seed;
  config.faults.packets = faults;
  Rig rig(config);
  Collector c;
  EXPECT_TRUE(rig.usb.start_iso(rig.cam, 0x82, {}, c.callback()));
  rig.start_depth();
  rig.usb.run_for(std::chrono::seconds(1));
  if (counters != nullptr) *counters = rig.device().depth_counters();
  return c.packets;
}

std::vector<std::uint8_t> seqs_under(const SimPacketFaults& faults, std::uint64_t seed,
                                     SimStreamCounters* counters = nullptr) {
  std::vector<std::uint8_t> seqs;
  for (const Packet& p : one_second(faults, seed, counters)) seqs.push_back(p.bytes[5]);
  return seqs;
}

TEST(SimKinectStream, DropRateDropsAboutThatShareSeededAndRepeatable) {
  SimPacketFaults f;
  f.drop_rate = 0.01;
  SimStreamCounters counters;
  const auto seqs = seqs_under(f, 7, &counters);
  std::size_t lost = 0;
  for (std::size_t i = 1; i < seqs.size(); ++i)
    lost += static_cast<std::uint8_t>(seqs[i] - seqs[i - 1] - 1);
  EXPECT_EQ(lost, counters.packets_dropped);  // every drop is a gap in the sequence numbers
  EXPECT_GT(counters.packets_generated, 7000U);
  const double share = double(counters.packets_dropped) / double(counters.packets_generated);
  EXPECT_GT(share, 0.006);
  EXPECT_LT(share, 0.014);
  EXPECT_EQ(seqs_under(f, 7), seqs);  // same seed, same packets
  EXPECT_NE(seqs_under(f, 8), seqs);
}

TEST(SimKinectStream, DuplicateReorderAndCorruptFaultsShowOnTheWire) {
  SimPacketFaults dup;
  dup.duplicate_rate = 0.01;
  SimStreamCounters counters;
  auto seqs = seqs_under(dup, 3, &counters);
  std::size_t repeats = 0;
  for (std::size_t i = 1; i < seqs.size(); ++i) repeats += seqs[i] == seqs[i - 1];
  EXPECT_GT(counters.packets_duplicated, 30U);
  EXPECT_EQ(repeats, counters.packets_duplicated);

  SimPacketFaults swap;
  swap.reorder_rate = 0.01;
  seqs = seqs_under(swap, 3, &counters);
  std::size_t backwards = 0;
  for (std::size_t i = 1; i < seqs.size(); ++i)
    backwards += static_cast<std::uint8_t>(seqs[i] - seqs[i - 1]) == 0xFF;
  EXPECT_GT(counters.packets_reordered, 30U);
  EXPECT_EQ(backwards, counters.packets_reordered);

  // Corruption keeps the packets and their order: compare with the clean run byte by byte.
  SimPacketFaults corrupt;
  corrupt.corrupt_rate = 0.05;
  const auto clean = one_second({}, 3);
  const auto hit = one_second(corrupt, 3, &counters);
  ASSERT_EQ(hit.size(), clean.size());
  std::size_t differing = 0;
  std::size_t in_header = 0;
  for (std::size_t i = 0; i < hit.size(); ++i) {
    ASSERT_EQ(hit[i].bytes.size(), clean[i].bytes.size());
    std::size_t bytes = 0;
    for (std::size_t j = 0; j < hit[i].bytes.size(); ++j) {
      if (hit[i].bytes[j] == clean[i].bytes[j]) continue;
      ++bytes;
      in_header += j < 12;
    }
    EXPECT_LE(bytes, 1U);  // one byte per corrupted packet
    differing += bytes;
  }
  EXPECT_GT(counters.packets_corrupted, 250U);
  EXPECT_EQ(differing, counters.packets_corrupted);
  EXPECT_LT(in_header, differing);  // most hits land in the payload
}

TEST(SimKinectStream, UnplugReportsNoDeviceAndTheKinectComesBackAtANewAddress) {
  SimKinectConfig config = cheap_config();
  config.faults.disconnect_at_ns = 100'000'000;
  config.faults.reconnect_at_ns = 300'000'000;
  Rig rig(config);
  const std::uint8_t old_address = rig.usb.enumerate(0x045E, 0x02AE)->front().address;
  Collector c;
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x82, {16, 16, 1920}, c.callback()));
  rig.start_depth();
  while (rig.usb.clock().now_ns() < 200'000'000)
    ASSERT_TRUE(rig.usb.handle_events(milliseconds(20)));
  const auto no_device = std::count_if(c.packets.begin(), c.packets.end(), [](const Packet& p) {
    return p.status == UsbPacketStatus::NO_DEVICE;
  });
  EXPECT_EQ(no_device, 256);  // 16 transfers x 16 packets in flight
  EXPECT_EQ(c.packets.back().status, UsbPacketStatus::NO_DEVICE);
  const drivers::UsbIsoStats stats = *rig.usb.iso_stats(rig.cam, 0x82);
  EXPECT_EQ(stats.transfers_in_flight, 0U);
  EXPECT_EQ(stats.transfers_failed, 16U);
  EXPECT_FALSE(rig.usb.present(0));
  EXPECT_TRUE(rig.usb.enumerate(0x045E, std::nullopt)->empty());
  std::vector<std::uint8_t> reply;
  EXPECT_EQ(gm_read(rig.usb, rig.cam, reply).error().code, Code::NO_DEVICE);
  rig.usb.run_for(milliseconds(150));
  ASSERT_TRUE(rig.usb.present(0));
  const auto back = rig.usb.enumerate(0x045E, 0x02AE);
  ASSERT_EQ(back->size(), 1U);
  EXPECT_NE(back->front().address, old_address);
  EXPECT_EQ(gm_read(rig.usb, rig.cam, reply).error().code, Code::NO_DEVICE);  // old handle
  EXPECT_TRUE(rig.usb.stop_iso(rig.cam, 0x82));  // teardown still works
  auto cam_result = rig.usb.open(back->front());
  ASSERT_TRUE(cam_result);
  EXPECT_EQ(*rig.usb.kernel_driver_active(*cam_result, 0), true);  // gspca bound again
  EXPECT_FALSE(rig.device().reg(0x06).has_value());                // power-on registers
}

TEST(SimKinectStream, AnUnrequestedCancelReturnsEveryTransferCancelled) {
  SimKinectConfig config = cheap_config();
  config.faults.cancel_at_ns = 50'000'000;
  Rig rig(config);
  Collector c;
  ASSERT_TRUE(rig.usb.start_iso(rig.cam, 0x82, {8, 16, 1920}, c.callback()));
  rig.start_depth();
  rig.usb.run_for(milliseconds(100));
  const auto cancelled = std::count_if(c.packets.begin(), c.packets.end(), [](const Packet& p) {
    return p.status == UsbPacketStatus::CANCELLED;
  });
  EXPECT_EQ(cancelled, 8 * 16);
  EXPECT_EQ(rig.usb.iso_stats(rig.cam, 0x82)->transfers_in_flight, 0U);
  EXPECT_TRUE(rig.usb.present(0));
  write_reg(rig.usb, rig.cam, rig.tag, 0x06, 0);  // the device itself is still there
}

}  // namespace
}  // namespace orthoflow::simulation::test
