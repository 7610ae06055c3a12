// Models 1473 / K4W through the audio function (drivers/kinect/kinect_audio.hpp), part 1: the pure
// codecs on hand-made bytes (specs/USB_TESTING.md 3.2, "1473 firmware loader"; KINECT_V1.md 12).
// Part 2, the loader and the audio motor against the simulated audio function, is
// kinect_audio_sim_test.cpp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <vector>

#include "drivers/kinect/kinect_audio.hpp"

namespace orthoflow::drivers::kinect {
namespace {

template <std::size_t N>
std::array<std::byte, N> bytes(const std::array<unsigned, N>& values) {
  std::array<std::byte, N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = std::byte{static_cast<std::uint8_t>(values[i])};
  return out;
}

void put32(std::span<std::byte> out, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i)
    out[at + i] = std::byte{static_cast<std::uint8_t>(v >> (8 * i))};
}

std::array<std::byte, 12> status_bytes(std::uint32_t magic, std::uint32_t tag, std::uint32_t s) {
  std::array<std::byte, 12> out{};
  put32(out, 0, magic);
  put32(out, 4, tag);
  put32(out, 8, s);
  return out;
}

std::vector<std::byte> image(std::uint32_t magic, std::uint32_t size, std::size_t file_bytes) {
  FirmwareHeader h;
  h.magic = magic;
  h.version = {1, 2, 3, 4};
  h.base_addr = 0x00080000;
  h.size = size;
  h.entry_addr = 0x00080100;
  std::vector<std::byte> file(file_bytes, std::byte{0x5A});
  const auto head = encode_firmware_header(h);
  std::copy(head.begin(), head.begin() + std::min(head.size(), file.size()), file.begin());
  return file;
}

TEST(KinectAudioCodec, BootloaderCommandIsSixLittleEndianWords) {
  const auto frame = encode_bootloader_command({0x01020304, 0x4000, 3, 0x00084000});
  const auto expected =
      bytes<24>({0x09, 0x20, 0x02, 0x06, 0x04, 0x03, 0x02, 0x01, 0x00, 0x40, 0x00, 0x00,
                 0x03, 0x00, 0x00, 0x00, 0x00, 0x40, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00});
  EXPECT_EQ(frame, expected);
  const auto execute = encode_bootloader_command({7, 0, 4, 0x00080100});
  EXPECT_EQ(execute[4], std::byte{7});
  EXPECT_EQ(execute[12], std::byte{4});
  EXPECT_EQ(execute[8], std::byte{0});
  EXPECT_EQ(execute[17], std::byte{0x01});
  EXPECT_EQ(execute[18], std::byte{0x08});
}

TEST(KinectAudioCodec, StatusChecksLengthMagicTagAndStatus) {
  const auto ok = status_bytes(AUDIO_STATUS_MAGIC, 5, 0);
  EXPECT_EQ(ok[0], std::byte{0x00});
  EXPECT_EQ(ok[1], std::byte{0xE0});
  EXPECT_EQ(ok[2], std::byte{0x6F});
  EXPECT_EQ(ok[3], std::byte{0x0A});
  EXPECT_EQ(check_audio_status(ok, 5), AudioStatusCheck::OK);
  EXPECT_EQ(check_audio_status(ok, 6), AudioStatusCheck::WRONG_TAG);
  EXPECT_EQ(check_audio_status(std::span<const std::byte>(ok).first(11), 5),
            AudioStatusCheck::WRONG_LENGTH);
  EXPECT_EQ(check_audio_status({}, 5), AudioStatusCheck::WRONG_LENGTH);
  std::array<std::byte, 13> longer{};
  std::copy(ok.begin(), ok.end(), longer.begin());
  EXPECT_EQ(check_audio_status(longer, 5), AudioStatusCheck::WRONG_LENGTH);
  EXPECT_EQ(check_audio_status(status_bytes(0x0A6FE001, 5, 0), 5), AudioStatusCheck::BAD_MAGIC);
  // The magic is checked before the tag, the tag before the status.
  EXPECT_EQ(check_audio_status(status_bytes(0, 9, 3), 5), AudioStatusCheck::BAD_MAGIC);
  EXPECT_EQ(check_audio_status(status_bytes(AUDIO_STATUS_MAGIC, 9, 3), 5),
            AudioStatusCheck::WRONG_TAG);
  EXPECT_EQ(check_audio_status(status_bytes(AUDIO_STATUS_MAGIC, 5, 3), 5),
            AudioStatusCheck::DEVICE_STATUS);
  const auto decoded = decode_audio_status(status_bytes(AUDIO_STATUS_MAGIC, 5, 3));
  ASSERT_TRUE(decoded.has_value());
  EXPECT_EQ(decoded->status, 3U);
  EXPECT_EQ(decoded->tag, 5U);
  EXPECT_STREQ(to_string(AudioStatusCheck::DEVICE_STATUS), "device_status");
}

TEST(KinectAudioCodec, FirmwareHeaderParsesAndRefusesBadImages) {
  const auto good = image(AUDIO_FIRMWARE_MAGIC, 100, 120);
  EXPECT_EQ(good[0], std::byte{0x0D});
  EXPECT_EQ(good[1], std::byte{0xF0});
  EXPECT_EQ(good[2], std::byte{0x77});
  EXPECT_EQ(good[3], std::byte{0xCA});
  auto h = parse_firmware_header(good);
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->version, (std::array<std::uint16_t, 4>{1, 2, 3, 4}));
  EXPECT_EQ(h->base_addr, 0x00080000U);
  EXPECT_EQ(h->size, 100U);
  EXPECT_EQ(h->entry_addr, 0x00080100U);
  EXPECT_EQ(parse_firmware_header(image(AUDIO_FIRMWARE_MAGIC, 120, 120)).has_value(), true);

  EXPECT_EQ(parse_firmware_header(std::span<const std::byte>(good).first(23)).error(),
            FirmwareCheck::TOO_SHORT);
  EXPECT_EQ(parse_firmware_header(image(0xCA77F00E, 100, 120)).error(), FirmwareCheck::BAD_MAGIC);
  EXPECT_EQ(parse_firmware_header(image(AUDIO_FIRMWARE_MAGIC, 23, 120)).error(),
            FirmwareCheck::SIZE_TOO_SMALL);
  EXPECT_EQ(parse_firmware_header(image(AUDIO_FIRMWARE_MAGIC, 121, 120)).error(),
            FirmwareCheck::SIZE_BEYOND_FILE);
  EXPECT_EQ(parse_firmware_header(image(AUDIO_FIRMWARE_MAGIC, 0xFFFFFFF0U, 120)).error(),
            FirmwareCheck::SIZE_ABSURD);
  EXPECT_EQ(parse_firmware_header(image(AUDIO_FIRMWARE_MAGIC, FIRMWARE_MAX_BYTES + 1, 120)).error(),
            FirmwareCheck::SIZE_ABSURD);
  auto wraps = image(AUDIO_FIRMWARE_MAGIC, 100, 120);
  put32(wraps, 12, 0xFFFFFFF0U);  // base_addr + size past 2^32
  EXPECT_EQ(parse_firmware_header(wraps).error(), FirmwareCheck::SIZE_ABSURD);
  EXPECT_STREQ(to_string(FirmwareCheck::SIZE_BEYOND_FILE), "size_beyond_file");
}

TEST(KinectAudioCodec, MotorCommandIsFiveLittleEndianWords) {
  const auto frame =
      encode_audio_motor_command({2, 0, AUDIO_CMD_TILT, encode_audio_tilt(-5).value()});
  const auto expected = bytes<20>({0x09, 0x20, 0x02, 0x06, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00,
                                   0x00, 0x00, 0x3B, 0x80, 0x00, 0x00, 0xFB, 0xFF, 0xFF, 0xFF});
  EXPECT_EQ(frame, expected);
  const auto state = encode_audio_motor_command({9, AUDIO_STATE_ARG1, AUDIO_CMD_STATE, 0});
  EXPECT_EQ(state[8], std::byte{0x68});
  EXPECT_EQ(state[12], std::byte{0x32});
  EXPECT_EQ(state[13], std::byte{0x80});
}

TEST(KinectAudioCodec, LedCodesMapYellowToGreen) {
  EXPECT_EQ(audio_led_code(LedMode::OFF), 1U);
  EXPECT_EQ(audio_led_code(LedMode::BLINK_GREEN), 2U);
  EXPECT_EQ(audio_led_code(LedMode::GREEN), 3U);
  EXPECT_EQ(audio_led_code(LedMode::RED), 4U);
  EXPECT_EQ(audio_led_code(LedMode::YELLOW), 3U);
  EXPECT_EQ(audio_led_code(LedMode::BLINK_RED_YELLOW), 2U);
}

TEST(KinectAudioCodec, TiltIsSignedWholeDegreesAndRefusedBeyondLimit) {
  EXPECT_EQ(encode_audio_tilt(0).value(), 0U);
  EXPECT_EQ(encode_audio_tilt(31).value(), 31U);
  EXPECT_EQ(encode_audio_tilt(-31).value(), 0xFFFFFFE1U);
  EXPECT_EQ(encode_audio_tilt(12.5).value(), 13U);  // halves away from zero
  EXPECT_EQ(encode_audio_tilt(-12.5).value(), static_cast<std::uint32_t>(-13));
  EXPECT_EQ(encode_audio_tilt(10.4).value(), 10U);
  EXPECT_FALSE(encode_audio_tilt(31.01).has_value());  // refused, never clipped
  EXPECT_FALSE(encode_audio_tilt(-32).has_value());
  EXPECT_FALSE(encode_audio_tilt(std::numeric_limits<double>::quiet_NaN()).has_value());
  EXPECT_FALSE(encode_audio_tilt(std::numeric_limits<double>::infinity()).has_value());
}

TEST(KinectAudioCodec, StateBlockDecodesInt32sAtOffsets16To31) {
  std::array<std::byte, AUDIO_STATE_BLOCK_BYTES> block{};
  for (std::size_t i = 0; i < block.size(); ++i) block[i] = std::byte{0xEE};  // the rest is ignored
  put32(block, 16, static_cast<std::uint32_t>(-12));
  put32(block, 20, 819);
  put32(block, 24, 100000);
  put32(block, 28, static_cast<std::uint32_t>(-7));
  const auto s = decode_audio_motor_state(block);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->accel_counts, (std::array<std::int32_t, 3>{-12, 819, 100000}));
  EXPECT_DOUBLE_EQ(s->accel_g[1], 1.0);
  EXPECT_DOUBLE_EQ(s->accel_mps2[1], 9.80665);
  EXPECT_EQ(s->tilt_deg, -7);
  EXPECT_FALSE(decode_audio_motor_state(std::span<const std::byte>(block).first(103)).has_value());
  std::array<std::byte, 105> longer{};
  EXPECT_FALSE(decode_audio_motor_state(longer).has_value());

  const MotorState m = to_motor_state(*s);
  EXPECT_EQ(m.accel_counts[0], -12);
  EXPECT_EQ(m.accel_counts[2], 32767);             // saturated ...
  EXPECT_DOUBLE_EQ(m.accel_g[2], 100000 / 819.0);  // ... but not in g
  EXPECT_EQ(m.tilt_raw, -14);                      // libfreenect's half degrees
  EXPECT_DOUBLE_EQ(m.tilt_deg.value(), -7.0);
  EXPECT_EQ(m.status, TiltStatus::UNKNOWN);
  AudioMotorState far;
  far.tilt_deg = 90;
  EXPECT_EQ(to_motor_state(far).tilt_raw, TILT_RAW_NO_READING);
  EXPECT_DOUBLE_EQ(to_motor_state(far).tilt_deg.value(), 90.0);
}

TEST(KinectAudioCodec, FirmwareStateFromInterfaceCountAndAudioPids) {
  UsbDeviceInfo d;
  EXPECT_EQ(audio_firmware_state(d), AudioFirmware::UNKNOWN);
  d.interface_count = 1;
  EXPECT_EQ(audio_firmware_state(d), AudioFirmware::BOOTLOADER);
  d.interface_count = 2;
  EXPECT_EQ(audio_firmware_state(d), AudioFirmware::RUNNING);
  d.interface_count = 4;
  EXPECT_EQ(audio_firmware_state(d), AudioFirmware::RUNNING);
  for (const unsigned pid : {0x02ADU, 0x02BEU, 0x02C3U, 0x02BBU})
    EXPECT_TRUE(is_audio_pid(static_cast<std::uint16_t>(pid)));
  EXPECT_FALSE(is_audio_pid(0x02AE));
  EXPECT_FALSE(is_audio_pid(0x02B0));
}

TEST(KinectAudioCodec, FirmwareSearchOrderFollowsLibfreenect) {
  ASSERT_EQ(setenv("LIBFREENECT_FIRMWARE_PATH", "/opt/fw", 1), 0);
  ASSERT_EQ(setenv("HOME", "/home/k", 1), 0);
  const auto paths = firmware_search_paths();
  EXPECT_EQ(paths,
            (std::vector<std::string>{"/opt/fw", ".", "/home/k/.libfreenect",
                                      "/usr/local/share/libfreenect", "/usr/share/libfreenect"}));
  ASSERT_EQ(unsetenv("LIBFREENECT_FIRMWARE_PATH"), 0);
  EXPECT_EQ(firmware_search_paths().front(), ".");
}

TEST(KinectAudioCodec, UnreadableFileIsANamedError) {
  auto read = read_firmware_file("/nonexistent/orthoflow/audios.bin");
  ASSERT_FALSE(read.has_value());
  EXPECT_EQ(read.error().code, FirmwareError::Code::FILE_UNREADABLE);
  EXPECT_EQ(to_string(read.error()), "file_unreadable");
  FirmwareError e;
  e.code = FirmwareError::Code::DEVICE_STATUS;
  e.cmd = 3;
  e.chunk = 1;
  e.tag = 1;
  e.status = 5;
  EXPECT_EQ(to_string(e), "device_status: cmd 3, chunk 1, tag 1, status 5");
}

}  // namespace
}  // namespace orthoflow::drivers::kinect
