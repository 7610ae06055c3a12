// Models 1473 / K4W through the audio function (drivers/kinect/kinect_audio.hpp), part 2:
// FirmwareLoader, AudioMotor and KinectMotor's audio backend against the simulated audio function
// (simulation/devices/sim_kinect_device.hpp) on simulated time. The simulator implements
// KINECT_V1.md 12 and has never been compared with a real Kinect. Images are synthetic (a valid
// header, then counting bytes): the real audios.bin is not redistributable. Part 1 is
// kinect_audio_test.cpp.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <vector>

#include "drivers/kinect/kinect_audio.hpp"
#include "drivers/kinect/kinect_camera.hpp"
#include "drivers/kinect/kinect_motor.hpp"
#include "simulation/devices/sim_usb_transport.hpp"

namespace orthoflow::drivers::kinect {
namespace {

using simulation::KinectModel;
using simulation::SimAudioState;
using simulation::SimKinectConfig;
using simulation::SimUsbTransport;
using namespace std::chrono_literals;

constexpr std::uint32_t BASE = 0x00080000;
constexpr std::uint32_t ENTRY = 0x00080200;

std::vector<std::byte> synthetic_image(std::uint32_t size, std::size_t extra = 0) {
  std::vector<std::byte> file(size + extra);
  for (std::size_t i = 0; i < file.size(); ++i)
    file[i] = std::byte{static_cast<std::uint8_t>(i * 7)};
  FirmwareHeader h;
  h.magic = AUDIO_FIRMWARE_MAGIC;
  h.version = {0, 1, 2, 3};
  h.base_addr = BASE;
  h.size = size;
  h.entry_addr = ENTRY;
  const auto head = encode_firmware_header(h);
  std::copy(head.begin(), head.end(), file.begin());
  return file;
}

SimKinectConfig config(KinectModel model) {
  SimKinectConfig c;
  c.model = model;
  return c;
}

CameraInfo first_camera(SimUsbTransport& usb) {
  auto cameras = list_cameras(usb);
  EXPECT_TRUE(cameras.has_value());
  EXPECT_FALSE(cameras.value().empty());
  return cameras.value().front();
}

Result<UsbDeviceInfo, FirmwareError> upload(SimUsbTransport& usb, std::span<const std::byte> image,
                                            FirmwareLoader& loader) {
  auto audio = loader.find_audio(first_camera(usb));
  EXPECT_TRUE(audio.has_value());
  if (!audio) return err(audio.error());
  return loader.upload(audio.value(), image);
}

TEST(KinectAudioSim, Uploads40KbImageInChunksOf0x4000AndBulkWritesOf512) {
  for (const KinectModel model : {KinectModel::K1473, KinectModel::K4W}) {
    SimUsbTransport usb;
    usb.add_kinect(config(model));
    FirmwareLoader loader(usb);
    auto before = loader.find_audio(first_camera(usb));
    ASSERT_TRUE(before.has_value());
    EXPECT_EQ(audio_firmware_state(before.value()), AudioFirmware::BOOTLOADER);
    const auto image = synthetic_image(40 * 1024, 100);  // the file is longer than `size`
    auto after = loader.upload(before.value(), image);
    ASSERT_TRUE(after.has_value()) << to_string(after.error());
    EXPECT_EQ(audio_firmware_state(after.value()), AudioFirmware::RUNNING);
    EXPECT_GE(after->interface_count, 2);
    EXPECT_EQ(after->serial.view(), before->serial.view());
    EXPECT_NE(after->address, before->address);

    const auto& sim = usb.kinect(0);
    ASSERT_EQ(sim.audio_commands().size(), 4U);
    const std::array<std::uint32_t, 3> lengths = {0x4000, 0x4000, 0x2000};
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(sim.audio_commands()[i].tag, i);
      EXPECT_EQ(sim.audio_commands()[i].cmd, 3U);
      EXPECT_EQ(sim.audio_commands()[i].word2, lengths[i]);
      EXPECT_EQ(sim.audio_commands()[i].word4, BASE + 0x4000 * i);
      EXPECT_EQ(sim.audio_commands()[i].status, 0U);
    }
    EXPECT_EQ(sim.audio_commands()[3].tag, 3U);
    EXPECT_EQ(sim.audio_commands()[3].cmd, 4U);
    EXPECT_EQ(sim.audio_commands()[3].word2, 0U);
    EXPECT_EQ(sim.audio_commands()[3].word4, ENTRY);
    EXPECT_EQ(sim.audio_data_writes(), std::vector<std::size_t>(80, 512));
    ASSERT_EQ(sim.audio_image().size(), 40U * 1024);
    for (std::size_t i = 0; i < sim.audio_image().size(); ++i)
      ASSERT_EQ(sim.audio_image()[i], std::to_integer<std::uint8_t>(image[i])) << i;
    EXPECT_EQ(loader.stats().chunks, 3U);
    EXPECT_EQ(loader.stats().commands, 4U);
    EXPECT_EQ(loader.stats().bulk_writes, 80U);
    EXPECT_EQ(loader.stats().bytes, 40U * 1024);
    EXPECT_EQ(usb.kinect(0).audio_state(usb.clock().now_ns()), SimAudioState::RUNNING);

    // A second upload sees the firmware running and sends nothing.
    auto again = loader.upload(after.value(), image);
    ASSERT_TRUE(again.has_value());
    EXPECT_EQ(usb.kinect(0).audio_commands().size(), 4U);
  }
}

TEST(KinectAudioSim, OddSizedImageEndsWithAShortChunkAndShortWrite) {
  SimUsbTransport usb;
  usb.add_kinect(config(KinectModel::K1473));
  FirmwareLoader loader(usb);
  auto after = upload(usb, synthetic_image(40000), loader);
  ASSERT_TRUE(after.has_value()) << to_string(after.error());
  const auto& sim = usb.kinect(0);
  ASSERT_EQ(sim.audio_commands().size(), 4U);
  EXPECT_EQ(sim.audio_commands()[2].word2, 40000U - 2 * 0x4000);
  std::vector<std::size_t> writes(2 * 32 + 14, 512);
  writes.push_back(40000 - 2 * 0x4000 - 14 * 512);
  EXPECT_EQ(sim.audio_data_writes(), writes);
  EXPECT_EQ(sim.audio_image().size(), 40000U);
}

TEST(KinectAudioSim, BadStatusOnAChunkAbortsWithDeviceStatus) {
  SimUsbTransport usb;
  auto c = config(KinectModel::K1473);
  c.faults.audio_bad_status_chunk = 1;
  usb.add_kinect(c);
  FirmwareLoader loader(usb);
  auto result = upload(usb, synthetic_image(40 * 1024), loader);
  ASSERT_FALSE(result.has_value());
  EXPECT_EQ(result.error().code, FirmwareError::Code::DEVICE_STATUS);
  EXPECT_EQ(result.error().chunk, 1U);
  EXPECT_EQ(result.error().tag, 1U);
  EXPECT_EQ(result.error().cmd, 3U);
  EXPECT_NE(result.error().status, 0U);
  EXPECT_EQ(usb.kinect(0).audio_commands().size(), 2U);  // no further chunk, no execute
  EXPECT_EQ(usb.kinect(0).audio_state(usb.clock().now_ns()), SimAudioState::BOOTLOADER);
}

TEST(KinectAudioSim, WrongStatusTagIsABadStatus) {
  SimUsbTransport usb;
  auto c = config(KinectModel::K1473);
  c.faults.audio_wrong_tag_once = true;
  usb.add_kinect(c);
  FirmwareLoader loader(usb);
  auto result = upload(usb, synthetic_image(1000), loader);
  ASSERT_FALSE(result.has_value());
  EXPECT_EQ(result.error().code, FirmwareError::Code::BAD_STATUS);
  EXPECT_EQ(result.error().status_check, AudioStatusCheck::WRONG_TAG);
  EXPECT_EQ(result.error().tag, 0U);
}

TEST(KinectAudioSim, NoReenumerationTimesOutAfterTenTries) {
  SimUsbTransport usb;
  auto c = config(KinectModel::K1473);
  c.faults.audio_no_reenumeration = true;
  usb.add_kinect(c);
  FirmwareLoader loader(usb);
  const std::int64_t start = usb.clock().now_ns();
  auto result = upload(usb, synthetic_image(40 * 1024), loader);
  ASSERT_FALSE(result.has_value());
  EXPECT_EQ(result.error().code, FirmwareError::Code::NO_REENUMERATION);
  EXPECT_EQ(loader.stats().enumerations, 10U);
  const std::int64_t elapsed = usb.clock().now_ns() - start;
  EXPECT_GE(elapsed, 10'000'000'000);
  EXPECT_LT(elapsed, 11'000'000'000);  // bounded: 10 x 1 s plus the upload
  EXPECT_EQ(usb.kinect(0).audio_state(usb.clock().now_ns()), SimAudioState::GONE);
}

TEST(KinectAudioSim, BackInBootloaderStateIsNotRunning) {
  SimUsbTransport usb;
  auto c = config(KinectModel::K1473);
  c.faults.audio_back_as_bootloader = true;
  usb.add_kinect(c);
  FirmwareLoader loader(usb);
  auto result = upload(usb, synthetic_image(2000), loader);
  ASSERT_FALSE(result.has_value());
  EXPECT_EQ(result.error().code, FirmwareError::Code::NOT_RUNNING);
}

TEST(KinectAudioSim, StalledTransferIsABoundedUsbTimeout) {
  SimUsbTransport usb;
  auto c = config(KinectModel::K1473);
  c.faults.audio_bulk_stalls = 1;
  usb.add_kinect(c);
  FirmwareLoader loader(usb);
  const std::int64_t start = usb.clock().now_ns();
  auto result = upload(usb, synthetic_image(2000), loader);
  ASSERT_FALSE(result.has_value());
  EXPECT_EQ(result.error().code, FirmwareError::Code::USB);
  EXPECT_EQ(result.error().usb.code, UsbError::Code::TIMEOUT);
  EXPECT_LE(usb.clock().now_ns() - start, 300'000'000);
}

TEST(KinectAudioSim, BadImageAndMissingAudioSendNothing) {
  SimUsbTransport usb;
  usb.add_kinect(config(KinectModel::K1473));
  FirmwareLoader loader(usb);
  auto bad = synthetic_image(2000);
  bad[0] = std::byte{0};
  auto result = upload(usb, bad, loader);
  ASSERT_FALSE(result.has_value());
  EXPECT_EQ(result.error().code, FirmwareError::Code::BAD_IMAGE);
  EXPECT_EQ(result.error().image, FirmwareCheck::BAD_MAGIC);
  EXPECT_TRUE(usb.kinect(0).audio_commands().empty());

  SimUsbTransport bare;
  auto c = config(KinectModel::K1473);
  c.with_audio = false;
  bare.add_kinect(c);
  FirmwareLoader none(bare);
  auto missing = none.find_audio(first_camera(bare));
  ASSERT_FALSE(missing.has_value());
  EXPECT_EQ(missing.error().code, FirmwareError::Code::NO_AUDIO_DEVICE);
}

TEST(KinectAudioSim, MotorRefusesUntilTheFirmwareRunsThenTiltsLedsAndReads) {
  for (const KinectModel model : {KinectModel::K1473, KinectModel::K4W}) {
    SimUsbTransport usb;
    SimKinectConfig level = config(model);
    level.mount_pitch_deg = 0.0;  // the accelerometer then reads the motor angle alone
    usb.add_kinect(level);
    auto refused = KinectMotor::open(usb, first_camera(usb));
    ASSERT_FALSE(refused.has_value());
    EXPECT_EQ(refused.error().usb.code, UsbError::Code::NOT_SUPPORTED);
    EXPECT_NE(to_string(refused.error()).find("upload the audio firmware first"),
              std::string::npos);

    FirmwareLoader loader(usb);
    ASSERT_TRUE(upload(usb, synthetic_image(40 * 1024), loader).has_value());
    const std::size_t boot_commands = usb.kinect(0).audio_commands().size();
    auto opened = KinectMotor::open(usb, first_camera(usb));
    ASSERT_TRUE(opened.has_value()) << to_string(opened.error());
    KinectMotor& motor = *opened.value();
    EXPECT_TRUE(is_audio_pid(motor.info().product));

    ASSERT_TRUE(motor.set_led(LedMode::RED).has_value());
    EXPECT_EQ(usb.kinect(0).audio_led(), 4U);
    ASSERT_TRUE(motor.set_led(LedMode::YELLOW).has_value());
    EXPECT_EQ(usb.kinect(0).audio_led(), 3U);  // no yellow: green

    ASSERT_TRUE(motor.set_tilt(20).has_value());
    auto moving = motor.read_state();
    ASSERT_TRUE(moving.has_value());
    EXPECT_LT(moving->tilt_deg.value(), 20.0);  // slewing at 15 deg/s
    usb.run_for(2s);
    auto state = motor.read_state();
    ASSERT_TRUE(state.has_value()) << to_string(state.error());
    EXPECT_DOUBLE_EQ(state->tilt_deg.value(), 20.0);
    EXPECT_EQ(state->tilt_raw, 40);
    const double rad = 20.0 * 3.14159265358979323846 / 180.0;
    EXPECT_EQ(state->accel_counts[1], std::lround(819 * std::cos(rad)));
    EXPECT_EQ(state->accel_counts[2], std::lround(819 * std::sin(rad)));
    EXPECT_NEAR(state->accel_g[1], std::cos(rad), 1e-3);

    auto limit = motor.set_tilt(31.5);  // refused, never clipped: nothing sent
    ASSERT_FALSE(limit.has_value());
    EXPECT_EQ(limit.error().code, KinectError::Code::INVALID_ARGUMENT);

    const auto& cmds = usb.kinect(0).audio_commands();
    ASSERT_EQ(cmds.size(), boot_commands + 5);
    const std::array<std::uint32_t, 5> codes = {AUDIO_CMD_LED, AUDIO_CMD_LED, AUDIO_CMD_TILT,
                                                AUDIO_CMD_STATE, AUDIO_CMD_STATE};
    for (std::size_t i = 0; i < 5; ++i) {
      EXPECT_EQ(cmds[boot_commands + i].tag, i);  // the motor's tags start at 0 and increment
      EXPECT_EQ(cmds[boot_commands + i].cmd, codes[i]);
      EXPECT_EQ(cmds[boot_commands + i].status, 0U);
    }
    EXPECT_EQ(cmds[boot_commands + 2].word4, 20U);
    EXPECT_EQ(cmds[boot_commands + 3].word2, AUDIO_STATE_ARG1);
    EXPECT_EQ(motor.stats().requests, 5U);
  }
}

TEST(KinectAudioSim, WaitUntilStillInfersStoppedFromTheTarget) {
  SimUsbTransport usb;
  auto c = config(KinectModel::K1473);
  c.audio_firmware_running = true;
  usb.add_kinect(c);
  auto opened = KinectMotor::open(usb, first_camera(usb));
  ASSERT_TRUE(opened.has_value()) << to_string(opened.error());
  KinectMotor& motor = *opened.value();
  auto first = motor.wait_until_still(1s);  // no tilt sent yet: the first reading
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->status, TiltStatus::UNKNOWN);
  ASSERT_TRUE(motor.set_tilt(-10).has_value());
  auto early = motor.wait_until_still(100ms);
  ASSERT_FALSE(early.has_value());
  EXPECT_EQ(early.error().usb.code, UsbError::Code::TIMEOUT);
  const std::int64_t start = usb.clock().now_ns();
  auto still = motor.wait_until_still(5s);
  ASSERT_TRUE(still.has_value()) << to_string(still.error());
  EXPECT_EQ(still->status, TiltStatus::STOPPED);
  EXPECT_DOUBLE_EQ(still->tilt_deg.value(), -10.0);
  EXPECT_LT(usb.clock().now_ns() - start, 1'000'000'000);  // 10 deg at 15 deg/s
}

TEST(KinectAudioSim, AudioMotorReportsBadStatusesAndTimeouts) {
  SimUsbTransport usb;
  auto c = config(KinectModel::K1473);
  c.audio_firmware_running = true;
  usb.add_kinect(c);
  auto opened = AudioMotor::open(usb, first_camera(usb));
  ASSERT_TRUE(opened.has_value()) << to_string(opened.error());
  AudioMotor& motor = *opened.value();
  auto f = usb.kinect(0).faults();
  f.audio_wrong_tag_once = true;
  usb.kinect(0).set_faults(f);
  auto wrong = motor.set_led(LedMode::GREEN);
  ASSERT_FALSE(wrong.has_value());
  EXPECT_EQ(wrong.error().code, KinectError::Code::BAD_REPLY);
  EXPECT_EQ(wrong.error().reply, ReplyCheck::WRONG_TAG);

  f = usb.kinect(0).faults();
  f.audio_bulk_stalls = 1;
  usb.kinect(0).set_faults(f);
  const std::int64_t start = usb.clock().now_ns();
  auto stalled = motor.set_tilt(5);
  ASSERT_FALSE(stalled.has_value());
  EXPECT_EQ(stalled.error().usb.code, UsbError::Code::TIMEOUT);
  EXPECT_LE(usb.clock().now_ns() - start, 110'000'000);  // the 100 ms command timeout
  EXPECT_EQ(motor.stats().timeouts, 1U);
  EXPECT_EQ(motor.tag(), 2U);

  auto ok = motor.read_state();
  ASSERT_TRUE(ok.has_value()) << to_string(ok.error());
  EXPECT_EQ(ok->tilt_deg, 0);

  // A 1414 camera has a motor function: the audio backend refuses it.
  SimUsbTransport k1414;
  k1414.add_kinect(SimKinectConfig{});
  auto not_audio = AudioMotor::open(k1414, first_camera(k1414));
  ASSERT_FALSE(not_audio.has_value());
  EXPECT_EQ(not_audio.error().usb.code, UsbError::Code::NOT_SUPPORTED);
}

// The simulated bootloader itself, driven by hand through the seam: it refuses what the loader
// above never sends.
struct RawBootloader {
  SimUsbTransport usb;
  UsbDeviceHandle handle;
  RawBootloader() {
    usb.add_kinect(config(KinectModel::K1473));
    FirmwareLoader loader(usb);
    auto audio = loader.find_audio(first_camera(usb));
    auto opened = usb.open(audio.value());
    handle = std::move(opened.value());
    EXPECT_TRUE(usb.claim_interface(handle, 0).has_value());
  }
  Result<std::size_t, UsbError> out(std::span<std::byte> data) {
    return usb.bulk(handle, AUDIO_ENDPOINT_OUT, data, UsbTimeout{100});
  }
  Result<std::size_t, UsbError> command(const BootloaderCommand& c) {
    auto frame = encode_bootloader_command(c);
    return out(frame);
  }
  std::uint32_t status(std::uint32_t tag) {
    std::array<std::byte, 12> reply{};
    auto got = usb.bulk(handle, AUDIO_ENDPOINT_IN, reply, UsbTimeout{100});
    EXPECT_TRUE(got.has_value());
    const auto s = decode_audio_status(reply);
    EXPECT_EQ(s->magic, AUDIO_STATUS_MAGIC);
    EXPECT_EQ(s->tag, tag);
    return s->status;
  }
  void send(std::span<std::byte> data) {
    for (std::size_t at = 0; at < data.size(); at += 512)
      ASSERT_TRUE(out(data.subspan(at, std::min<std::size_t>(512, data.size() - at))).has_value());
  }
};

TEST(KinectAudioSim, SimulatedBootloaderValidatesCommandsAndChunks) {
  auto image = synthetic_image(0x5000);
  {
    RawBootloader
        b;  // IN with nothing to answer: a timeout; a bad magic or an oversize write: PIPE
    std::array<std::byte, 12> reply{};
    EXPECT_EQ(b.usb.bulk(b.handle, AUDIO_ENDPOINT_IN, reply, UsbTimeout{100}).error().code,
              UsbError::Code::TIMEOUT);
    auto frame = encode_bootloader_command({0, 16, 3, BASE});
    frame[0] = std::byte{0};
    EXPECT_EQ(b.out(frame).error().code, UsbError::Code::PIPE);
    ASSERT_TRUE(b.command({0, 0x4000, 3, BASE}).has_value());
    EXPECT_EQ(b.out(std::span<std::byte>(image).first(513)).error().code, UsbError::Code::PIPE);
  }
  {
    RawBootloader b;  // a chunk longer than 0x4000 gets a nonzero status at once
    ASSERT_TRUE(b.command({0, 0x4001, 3, BASE}).has_value());
    EXPECT_NE(b.status(0), 0U);
  }
  {
    RawBootloader b;  // the header's magic is checked in the first chunk
    auto bad = image;
    bad[3] = std::byte{0};
    ASSERT_TRUE(b.command({0, 0x4000, 3, BASE}).has_value());
    b.send(std::span<std::byte>(bad).first(0x4000));
    EXPECT_NE(b.status(0), 0U);
  }
  {
    RawBootloader b;  // addresses must continue from base_addr; tags must increment
    ASSERT_TRUE(b.command({0, 0x4000, 3, BASE}).has_value());
    b.send(std::span<std::byte>(image).first(0x4000));
    EXPECT_EQ(b.status(0), 0U);
    ASSERT_TRUE(b.command({1, 0x1000, 3, BASE + 0x4100}).has_value());
    b.send(std::span<std::byte>(image).subspan(0x4000, 0x1000));
    EXPECT_NE(b.status(1), 0U);
    ASSERT_TRUE(b.command({5, 0x1000, 3, BASE + 0x4000}).has_value());
    b.send(std::span<std::byte>(image).subspan(0x4000, 0x1000));
    EXPECT_NE(b.status(5), 0U);
    ASSERT_TRUE(b.command({6, 0x1000, 3, BASE + 0x4000}).has_value());
    b.send(std::span<std::byte>(image).subspan(0x4000, 0x1000));
    EXPECT_EQ(b.status(6), 0U);
    ASSERT_TRUE(b.command({7, 0, 4, ENTRY + 4}).has_value());  // wrong entry address
    EXPECT_NE(b.status(7), 0U);
    ASSERT_TRUE(b.command({8, 0, 4, ENTRY}).has_value());
    EXPECT_EQ(b.status(8), 0U);
    EXPECT_EQ(b.usb.kinect(0).audio_state(b.usb.clock().now_ns()), SimAudioState::GONE);
    EXPECT_EQ(b.command({9, 0, 4, ENTRY}).error().code, UsbError::Code::NO_DEVICE);
    b.usb.run_for(2s);
    EXPECT_EQ(b.usb.kinect(0).audio_state(b.usb.clock().now_ns()), SimAudioState::RUNNING);
    EXPECT_EQ(b.usb.kinect(0).audio_image().size(), 0x5000U);
  }
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
