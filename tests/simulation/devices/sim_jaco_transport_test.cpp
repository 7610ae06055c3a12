// SimJacoTransport: enumeration, the seam contract, simulated time, the fault knobs, unplug and
// replug, the DSP >= 5 joystick quirk and determinism. The arm's behaviour: sim_jaco_test.cpp.
#include <vector>

#include "sim_jaco_test_support.hpp"

namespace orthoflow::simulation::test {
namespace {

using S = jaco::ArmState;
using C = jaco::Command;

TEST(SimJaco, EnumeratesAsKinovaWithOneInterfaceAndNoSerial) {
  SimJacoTransport usb;
  usb.add_arm(ready_config());
  SimJacoConfig second = sim_jaco_v1_config();
  second.port = 2;
  usb.add_arm(second);
  auto all = usb.enumerate(0x22CD, std::nullopt);
  ASSERT_TRUE(all);
  ASSERT_EQ(all->size(), 2U);
  const UsbDeviceInfo& a = all->front();
  EXPECT_EQ(a.vendor, 0x22CD);
  EXPECT_EQ(a.product, 0x0000);
  EXPECT_EQ(a.interface_count, 1);
  EXPECT_TRUE(a.serial.empty());
  EXPECT_EQ(a.port_depth, 1);
  EXPECT_EQ(a.bus, (*all)[1].bus);
  EXPECT_NE(a.address, (*all)[1].address);
  EXPECT_EQ(usb.enumerate(0x22CD, 0x0000)->size(), 2U);
  EXPECT_TRUE(usb.enumerate(0x22CD, 0x0001)->empty());
  EXPECT_TRUE(usb.enumerate(0x045E, std::nullopt)->empty());
}

TEST(SimJaco, HandlesFollowTheSeamContract) {
  JacoRig rig;
  SimJacoTransport other;
  SimJacoTransport& usb = rig.usb;
  const UsbDeviceInfo info = usb.enumerate(0x22CD, std::nullopt)->front();
  auto second_result = usb.open(info);
  ASSERT_TRUE(second_result);
  UsbDeviceHandle second = std::move(*second_result);
  UsbDeviceInfo gone = info;
  gone.address = 99;
  EXPECT_EQ(usb.open(gone).error().code, Code::NO_DEVICE);
  EXPECT_EQ(other.claim_interface(rig.h, 0).error().code, Code::NOT_OPEN);
  EXPECT_EQ(usb.claim_interface(UsbDeviceHandle{}, 0).error().code, Code::NOT_OPEN);
  EXPECT_EQ(usb.claim_interface(second, 1).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.claim_interface(second, 0).error().code, Code::BUSY);
  EXPECT_EQ(usb.claim_interface(rig.h, 0).error().code, Code::BUSY);
  EXPECT_EQ(usb.release_interface(second, 0).error().code, Code::NOT_FOUND);
  jaco::Packet packet = jaco::make_request(C::GET_ANG_POS);
  EXPECT_EQ(usb.interrupt(second, jaco::EP_OUT, packet, TIMEOUT_1S).error().code, Code::NOT_FOUND);
  EXPECT_TRUE(usb.set_alt_setting(rig.h, 0, 0));
  EXPECT_EQ(usb.set_alt_setting(rig.h, 0, 1).error().code, Code::NOT_FOUND);
  EXPECT_FALSE(*usb.kernel_driver_active(rig.h, 0));
  EXPECT_EQ(usb.detach_kernel_driver(rig.h, 0).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.attach_kernel_driver(rig.h, 0).error().code, Code::NOT_FOUND);
  EXPECT_TRUE(usb.clear_halt(rig.h, 0x82));
  EXPECT_EQ(usb.clear_halt(rig.h, 0x81).error().code, Code::NOT_FOUND);
  std::array<std::byte, 8> small{};
  EXPECT_EQ(usb.control(rig.h, {0xC0, 0, 0, 0}, small, TIMEOUT_1S).error().code,
            Code::NOT_SUPPORTED);
  EXPECT_EQ(usb.bulk(rig.h, 0x82, small, TIMEOUT_1S).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.max_iso_packet_size(rig.h, 0x82).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.start_iso(rig.h, 0x82, {}, [](auto, auto, auto) {}).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.stop_iso(rig.h, 0x82).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.iso_stats(rig.h, 0x82).error().code, Code::NOT_FOUND);
  EXPECT_EQ(usb.interrupt(rig.h, 0x81, packet, TIMEOUT_1S).error().code, Code::NOT_FOUND);
  std::array<std::byte, 63> short_out{};
  EXPECT_EQ(usb.interrupt(rig.h, jaco::EP_OUT, short_out, TIMEOUT_1S).error().code,
            Code::INVALID_PARAM);
  EXPECT_EQ(rig.arm().counters().packets, 0U);
  EXPECT_EQ(usb.handle_events(UsbTimeout{-1}).error().code, Code::INVALID_PARAM);
  // An IN buffer under 64 bytes overflows (the reply is lost); a larger one gets 64.
  ASSERT_TRUE(rig.write(jaco::make_request(C::GET_ANG_POS)));
  std::array<std::byte, 32> tiny{};
  EXPECT_EQ(usb.interrupt(rig.h, jaco::EP_IN, tiny, TIMEOUT_1S).error().code, Code::OVERFLOW);
  ASSERT_TRUE(rig.write(jaco::make_request(C::GET_ANG_POS)));
  std::array<std::byte, 128> big{};
  EXPECT_EQ(*usb.interrupt(rig.h, jaco::EP_IN, big, TIMEOUT_1S), 64U);
  // Closing the claimant frees the interface.
  usb.close(rig.h);
  EXPECT_TRUE(usb.claim_interface(second, 0));
}

TEST(SimJaco, TransfersTakeTheirLatencyAndAnEmptyInItsWholeTimeout) {
  JacoRig rig;
  const std::int64_t t0 = rig.now();
  ASSERT_TRUE(rig.get(C::GET_ANG_POS));
  EXPECT_EQ(rig.now() - t0, 2 * MS);  // OUT + IN, 1 ms each
  jaco::Packet reply{};
  const std::int64_t t1 = rig.now();
  EXPECT_EQ(rig.read(reply, UsbTimeout{250}).error().code, Code::TIMEOUT);
  EXPECT_EQ(rig.now() - t1, 250 * MS);
  EXPECT_EQ(rig.read(reply, UsbTimeout{0}).error().code, Code::TIMEOUT);
  EXPECT_EQ(rig.now() - t1, 5250 * MS);  // timeout 0: infinite_wait
  const std::uint64_t cycles = rig.arm().counters().cycles;
  ASSERT_TRUE(rig.usb.handle_events(UsbTimeout{100}));
  EXPECT_EQ(rig.arm().counters().cycles, cycles + 10);
  // A given clock, moved by hand, is followed by the next call.
  drivers::ManualClock clock(7 * MS);
  SimJacoTransport usb(clock, {std::chrono::microseconds(125), UsbTimeout{100}, 2});
  usb.add_arm(ready_config());
  clock.advance(1s);
  ASSERT_TRUE(usb.handle_events(UsbTimeout{0}));
  EXPECT_EQ(usb.arm(0).counters().cycles, 100U);
  EXPECT_EQ(usb.arm(0).now_ns(), 1007 * MS);
}

TEST(SimJaco, GarbageCorruptAndWrongIdRepliesAreDetectable) {
  SimJacoConfig garbage = ready_config();
  garbage.faults.garbage_reply_rate = 1.0;
  SimJacoConfig corrupt = ready_config();
  corrupt.faults.corrupt_body_rate = 1.0;
  SimJacoConfig wrong = ready_config();
  wrong.faults.wrong_command_rate = 1.0;
  JacoRig g(garbage), c(corrupt), w(wrong);
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(jaco::check_reply(*g.get(C::GET_ANG_POS), C::GET_ANG_POS),
              jaco::PacketCheck::WRONG_COMMAND);
    const jaco::Packet bad = *c.get(C::GET_ANG_POS);
    EXPECT_EQ(jaco::check_reply(bad, C::GET_ANG_POS), jaco::PacketCheck::OK);
    jaco::NineFloats nine;
    EXPECT_EQ(jaco::parse_nine(bad, nine), jaco::PacketCheck::NOT_FINITE);
    EXPECT_EQ(jaco::read_header(*w.get(C::GET_ANG_POS)).command_id, 16);
  }
  EXPECT_EQ(g.arm().counters().garbage_replies, 100U);
  EXPECT_EQ(c.arm().counters().corrupt_replies, 100U);
  EXPECT_EQ(w.arm().counters().wrong_command_replies, 100U);
  // The commands still act: only their replies are bad.
  w.plain(C::START_API_CONTROL);
  EXPECT_TRUE(w.arm().api_control());
}

TEST(SimJaco, InTimeoutsAndDroppedOutsLeaveTheInEmpty) {
  SimJacoConfig silent = ready_config();
  silent.faults.in_timeout_rate = 1.0;
  SimJacoConfig lossy = ready_config();
  lossy.faults.drop_out_rate = 1.0;
  JacoRig s(silent), l(lossy);
  jaco::Packet reply{};
  for (JacoRig* rig : {&s, &l}) {
    ASSERT_TRUE(rig->write(jaco::make_plain_command(C::START_API_CONTROL)));
    const std::int64_t t0 = rig->now();
    EXPECT_EQ(rig->read(reply).error().code, Code::TIMEOUT);
    EXPECT_EQ(rig->now() - t0, 1000 * MS);
  }
  EXPECT_TRUE(s.arm().api_control());   // acted, reply suppressed
  EXPECT_FALSE(l.arm().api_control());  // never seen
  EXPECT_EQ(s.arm().counters().suppressed_replies, 1U);
  EXPECT_EQ(l.arm().counters().dropped_outs, 1U);
  // At a rate of 0.3 about 30% go missing.
  SimJacoConfig some = ready_config();
  some.faults.in_timeout_rate = 0.3;
  JacoRig r(some);
  int lost = 0;
  for (int i = 0; i < 400; ++i) {
    ASSERT_TRUE(r.write(jaco::make_request(C::GET_ANG_POS)));
    if (!r.read(reply, UsbTimeout{5})) ++lost;
  }
  EXPECT_GT(lost, 80);
  EXPECT_LT(lost, 160);
  EXPECT_EQ(static_cast<std::uint64_t>(lost), r.arm().counters().suppressed_replies);
}

TEST(SimJaco, StaleRepliesWaitForTheFlushAndResetDropsPendingReplies) {
  SimJacoConfig c = ready_config();
  c.faults.stale_replies = 3;
  JacoRig rig(c);
  jaco::Packet reply{};
  int flushed = 0;
  while (rig.read(reply, UsbTimeout{1000})) {
    EXPECT_EQ(jaco::read_header(reply).command_id, 15);
    ++flushed;
  }
  EXPECT_EQ(flushed, 3);
  ASSERT_TRUE(rig.write(jaco::make_request(C::GET_FIRMWARE)));
  ASSERT_TRUE(rig.usb.reset_device(rig.h));  // loses the firmware reply, queues 3 stale again
  EXPECT_EQ(rig.arm().counters().replies_lost, 1U);
  ASSERT_TRUE(rig.read(reply));
  EXPECT_EQ(jaco::read_header(reply).command_id, 15);
}

TEST(SimJaco, UnplugAnswersNoDeviceWhileTheArmKeepsMoving) {
  SimJacoConfig c = ready_config();
  c.faults.unplug_at_ns = 300 * MS;
  JacoRig rig(c);
  rig.plain(C::START_API_CONTROL);
  jaco::JointAngles far = c.home_joints;
  far[0] += 30.0;
  rig.point(angular_position(far));
  ASSERT_TRUE(rig.write(jaco::make_request(C::GET_ANG_POS)));
  jaco::Packet reply{};
  ASSERT_TRUE(rig.read(reply));
  EXPECT_EQ(rig.read(reply).error().code, Code::NO_DEVICE);  // cut short at the unplug
  EXPECT_EQ(rig.now(), 300 * MS);
  EXPECT_FALSE(rig.usb.present(0));
  EXPECT_TRUE(rig.usb.enumerate(0x22CD, std::nullopt)->empty());
  EXPECT_EQ(rig.write(jaco::make_request(C::GET_ANG_POS)).error().code, Code::NO_DEVICE);
  EXPECT_EQ(rig.usb.claim_interface(rig.h, 0).error().code, Code::NO_DEVICE);
  EXPECT_TRUE(rig.arm().moving());  // the cable is gone, not the power: the point runs on
  rig.wait(1s);
  EXPECT_EQ(rig.arm().joints()[0], far[0]);
  rig.usb.replug(0);
  EXPECT_EQ(rig.write(jaco::make_request(C::GET_ANG_POS)).error().code, Code::NO_DEVICE);
  const auto list = rig.usb.enumerate(0x22CD, std::nullopt);
  ASSERT_EQ(list->size(), 1U);
  auto fresh = rig.usb.open(list->front());
  ASSERT_TRUE(fresh);
  ASSERT_TRUE(rig.usb.claim_interface(*fresh, 0));
  rig.h = std::move(*fresh);
  EXPECT_TRUE(rig.arm().api_control());  // still powered: its state survived
  EXPECT_EQ(rig.nine(C::GET_ANG_POS).values[0], static_cast<float>(far[0]));
  // By hand; and power_cycle() is the power switch.
  rig.usb.unplug(0);
  EXPECT_EQ(rig.write(jaco::make_request(C::GET_ANG_POS)).error().code, Code::NO_DEVICE);
  rig.arm().power_cycle(rig.now());
  EXPECT_EQ(rig.arm().state(), S::READY_STANDBY);
  EXPECT_FALSE(rig.arm().api_control());
}

TEST(SimJaco, Dsp5QuirkIgnoresALoneJoystickPacket) {
  for (const bool dsp5 : {true, false}) {
    SimJacoConfig c;  // NOINIT
    c.faults.fw5_ignore_first_joystick = true;
    if (!dsp5) c.dsp = {4, 2, 0};
    JacoRig rig(c);
    rig.plain(C::START_API_CONTROL);
    rig.joystick(jaco::home_button_press());
    rig.wait(10ms);
    EXPECT_EQ(rig.arm().state(), dsp5 ? S::NOINIT : S::NORMAL_TO_READY);
    rig.wait(500ms);
    rig.joystick(jaco::home_button_press());  // the double send, 100 ms apart (libkindrv)
    rig.wait(100ms);
    rig.joystick(jaco::home_button_press());
    EXPECT_EQ(rig.arm().state(), S::NORMAL_TO_READY);
    EXPECT_EQ(rig.arm().counters().joystick_ignored, dsp5 ? 2U : 0U);
  }
}

/// One scripted session with every random fault on: each transfer's outcome, bytes and time.
std::vector<std::uint64_t> faulty_session(std::uint64_t seed) {
  SimJacoConfig c = ready_config();
  c.fault_seed = seed;
  c.faults.drop_out_rate = 0.1;
  c.faults.in_timeout_rate = 0.1;
  c.faults.garbage_reply_rate = 0.1;
  c.faults.corrupt_body_rate = 0.1;
  c.faults.wrong_command_rate = 0.1;
  JacoRig rig(c);
  std::vector<std::uint64_t> log;
  const C script[] = {C::START_API_CONTROL, C::GET_ANG_POS, C::GET_ARM_STATUS, C::GET_ANG_VEL};
  for (int i = 0; i < 200; ++i) {
    const C command = script[i % 4];
    const jaco::Packet out =
        i % 4 == 0 ? jaco::make_plain_command(command) : jaco::make_request(command);
    jaco::Packet reply{};
    if (i % 7 == 3) {
      EXPECT_TRUE(rig.write(jaco::encode_trajectory(angular_velocity(0, 10.0F))));
      (void)rig.read(reply, UsbTimeout{20});
    }
    EXPECT_TRUE(rig.write(out));
    const auto r = rig.read(reply, UsbTimeout{20});
    log.push_back(r ? 0U : static_cast<std::uint64_t>(r.error().code) + 1);
    for (std::size_t b = 0; b < reply.size(); b += 8) {
      std::uint64_t word = 0;
      for (std::size_t k = 0; k < 8; ++k)
        word |= std::to_integer<std::uint64_t>(reply[b + k]) << (8 * k);
      log.push_back(word);
    }
    log.push_back(static_cast<std::uint64_t>(rig.now()));
  }
  return log;
}

TEST(SimJaco, SameSeedSameBytesAndTimes) {
  const auto a = faulty_session(7);
  EXPECT_EQ(a, faulty_session(7));
  EXPECT_NE(a, faulty_session(8));
}

}  // namespace
}  // namespace orthoflow::simulation::test
