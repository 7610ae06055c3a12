// SimKinectDevice: the audio function's bootloader and running firmware over bulk 0x01 / 0x81
// (KINECT_V1.md 12) and its re-enumeration after the firmware starts.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "simulation/devices/sim_bytes.hpp"
#include "simulation/devices/sim_kinect_device.hpp"

namespace orthoflow::simulation {

namespace {

// The audio protocol (KINECT_V1.md 12). Nonzero status values are our own: the brief names none.
constexpr std::uint32_t AUDIO_MAGIC = 0x06022009;
constexpr std::uint32_t AUDIO_STATUS_MAGIC = 0x0A6FE000;
constexpr std::uint32_t AUDIO_IMAGE_MAGIC = 0xCA77F00D;
constexpr std::size_t AUDIO_CHUNK_MAX = 0x4000;
constexpr std::size_t AUDIO_PACKET_MAX = 512;
constexpr std::uint32_t AUDIO_BAD_TAG = 1;
constexpr std::uint32_t AUDIO_BAD_LENGTH = 2;
constexpr std::uint32_t AUDIO_BAD_ADDRESS = 3;
constexpr std::uint32_t AUDIO_BAD_HEADER = 4;
constexpr std::uint32_t AUDIO_FAULT = 5;
constexpr std::uint32_t AUDIO_BAD_COMMAND = 6;
constexpr double AUDIO_TILT_LIMIT_DEG = 31.0;
constexpr double AUDIO_COUNTS_PER_G = 819.0;

}  // namespace

bool SimKinectDevice::present(KinectFunction function, std::int64_t now_ns) const noexcept {
  if (!has_function(function)) return false;
  if (function != KinectFunction::AUDIO || !audio_.gone_ns || now_ns < *audio_.gone_ns) return true;
  return audio_.back_ns && now_ns >= *audio_.back_ns;
}

SimAudioState SimKinectDevice::audio_state(std::int64_t now_ns) const noexcept {
  if (!present(KinectFunction::AUDIO, now_ns)) return SimAudioState::GONE;
  return audio_.running ? SimAudioState::RUNNING : SimAudioState::BOOTLOADER;
}

void SimKinectDevice::audio_power_on() noexcept {
  Audio fresh;
  fresh.running = config_.audio_firmware_running;
  fresh.generation = audio_.generation + 1;
  fresh.commands = std::move(audio_.commands);  // the logs survive, for tests
  fresh.data_writes = std::move(audio_.data_writes);
  audio_ = std::move(fresh);
}

SimControlReply SimKinectDevice::bulk(KinectFunction function, std::uint8_t endpoint,
                                      std::span<std::byte> data, std::int64_t now_ns) noexcept {
  if (function != KinectFunction::AUDIO || (endpoint != 0x01 && endpoint != 0x81))
    return {SimControlOutcome::PIPE, 0};
  if (faults_.audio_bulk_stalls > 0) {
    --faults_.audio_bulk_stalls;
    return {SimControlOutcome::TIMEOUT, 0};
  }
  return endpoint == 0x01 ? audio_out(data, now_ns) : audio_in(data, now_ns);
}

SimControlReply SimKinectDevice::audio_out(std::span<const std::byte> data,
                                           std::int64_t now_ns) noexcept {
  using Phase = Audio::Phase;
  if (audio_.phase == Phase::DATA) {
    if (data.empty() || data.size() > AUDIO_PACKET_MAX || data.size() > audio_.data_left)
      return {SimControlOutcome::PIPE, 0};
    audio_.data_writes.push_back(data.size());
    for (const std::byte b : data) audio_.chunk.push_back(std::to_integer<std::uint8_t>(b));
    audio_.data_left -= data.size();
    if (audio_.data_left == 0) bootloader_chunk_done();
    return {SimControlOutcome::OK, data.size()};
  }
  // A command while the previous answer is unread is refused (libfreenect always reads it).
  if (audio_.phase != Phase::IDLE) return {SimControlOutcome::PIPE, 0};
  if (data.size() < 16 || sim_get_le32(data, 0) != AUDIO_MAGIC) return {SimControlOutcome::PIPE, 0};
  if (audio_.running) {
    firmware_command(data, now_ns);
  } else {
    if (data.size() != 24) return {SimControlOutcome::PIPE, 0};
    bootloader_command(data);
  }
  return {SimControlOutcome::OK, data.size()};
}

void SimKinectDevice::bootloader_command(std::span<const std::byte> data) noexcept {
  using Phase = Audio::Phase;
  Audio& a = audio_;
  a.tag = sim_get_le32(data, 4);
  const std::uint32_t bytes = sim_get_le32(data, 8);
  a.cmd = sim_get_le32(data, 12);
  const std::uint32_t addr = sim_get_le32(data, 16);
  a.status = 0;
  if (a.tag_seen && a.tag != a.last_tag + 1) a.status = AUDIO_BAD_TAG;
  a.tag_seen = true;
  a.last_tag = a.tag;
  a.phase = Phase::STATUS;
  if (a.cmd == 0x03) {
    const std::uint32_t expected =
        a.have_header ? a.base_addr + static_cast<std::uint32_t>(a.image.size()) : addr;
    if (bytes == 0 || bytes > AUDIO_CHUNK_MAX) {
      if (a.status == 0) a.status = AUDIO_BAD_LENGTH;
    } else {
      if (a.status == 0 && addr != expected) a.status = AUDIO_BAD_ADDRESS;
      a.chunk_addr = addr;
      a.chunk.clear();
      a.data_left = bytes;
      a.phase = Phase::DATA;  // the data comes whatever the status; it is judged at the end
    }
    if (faults_.audio_bad_status_chunk && *faults_.audio_bad_status_chunk == a.chunks &&
        a.status == 0)
      a.status = AUDIO_FAULT;
    ++a.chunks;
  } else if (a.cmd == 0x04) {
    const bool complete = a.have_header && a.image.size() == a.size;
    if (a.status == 0 && (!complete || bytes != 0 || addr != a.entry_addr))
      a.status = AUDIO_BAD_COMMAND;
    a.execute_pending = a.status == 0;
  } else if (a.status == 0) {
    a.status = AUDIO_BAD_COMMAND;
  }
  a.commands.push_back({a.tag, a.cmd, bytes, addr, a.status});
}

void SimKinectDevice::bootloader_chunk_done() noexcept {
  Audio& a = audio_;
  a.phase = Audio::Phase::STATUS;
  if (a.status == 0 && !a.have_header) {
    const std::span<const std::uint8_t> c(a.chunk);
    if (c.size() < 24 || sim_get_le32(c, 0) != AUDIO_IMAGE_MAGIC ||
        sim_get_le32(c, 12) != a.chunk_addr || sim_get_le32(c, 16) < 24) {
      a.status = AUDIO_BAD_HEADER;
    } else {
      a.have_header = true;
      a.base_addr = sim_get_le32(c, 12);
      a.size = sim_get_le32(c, 16);
      a.entry_addr = sim_get_le32(c, 20);
    }
  }
  if (a.status == 0 && a.image.size() + a.chunk.size() > a.size) a.status = AUDIO_BAD_LENGTH;
  if (a.status == 0) a.image.insert(a.image.end(), a.chunk.begin(), a.chunk.end());
  a.commands.back().status = a.status;
}

void SimKinectDevice::firmware_command(std::span<const std::byte> data,
                                       std::int64_t now_ns) noexcept {
  Audio& a = audio_;
  a.tag = sim_get_le32(data, 4);
  const std::uint32_t arg1 = sim_get_le32(data, 8);
  a.cmd = sim_get_le32(data, 12);
  const std::uint32_t arg2 = data.size() >= 20 ? sim_get_le32(data, 16) : 0;
  a.status = 0;
  a.phase = Audio::Phase::STATUS;
  const double angle = tilt_deg(now_ns);
  if (a.cmd == 0x10 && data.size() >= 20 && arg2 >= 1 && arg2 <= 4) {
    a.led = arg2;
  } else if (a.cmd == 0x803B && data.size() >= 20) {
    const double wanted = static_cast<double>(static_cast<std::int32_t>(arg2));
    motor_.target_deg = std::clamp(wanted, -AUDIO_TILT_LIMIT_DEG, AUDIO_TILT_LIMIT_DEG);
    motor_.clamped = motor_.target_deg != wanted;
  } else if (a.cmd == 0x8032 && arg1 == 0x68) {
    // Gravity in the camera frame pitched by the mount plus `angle` (no roll), as the 1414 model.
    const double rad = (angle + mount_pitch_deg()) * 3.14159265358979323846 / 180.0;
    a.block.fill(std::byte{0});
    sim_put_le32(a.block, 16, 0);
    sim_put_le32(a.block, 20,
                 static_cast<std::uint32_t>(
                     static_cast<std::int32_t>(std::lround(AUDIO_COUNTS_PER_G * std::cos(rad)))));
    sim_put_le32(a.block, 24,
                 static_cast<std::uint32_t>(
                     static_cast<std::int32_t>(std::lround(AUDIO_COUNTS_PER_G * std::sin(rad)))));
    sim_put_le32(a.block, 28,
                 static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(angle))));
    a.phase = Audio::Phase::BLOCK;
  } else {
    a.status = AUDIO_BAD_COMMAND;
  }
  a.commands.push_back({a.tag, a.cmd, arg1, arg2, a.status});
}

SimControlReply SimKinectDevice::audio_in(std::span<std::byte> data, std::int64_t now_ns) noexcept {
  using Phase = Audio::Phase;
  Audio& a = audio_;
  if (a.phase == Phase::BLOCK) {
    const std::size_t n = std::min(a.block.size(), data.size());
    std::memcpy(data.data(), a.block.data(), n);
    a.phase = Phase::STATUS;
    return {SimControlOutcome::OK, n};
  }
  if (a.phase != Phase::STATUS) return {SimControlOutcome::TIMEOUT, 0};  // nothing to send
  std::array<std::byte, 12> status{};
  sim_put_le32(status, 0, AUDIO_STATUS_MAGIC);
  sim_put_le32(status, 4, faults_.audio_wrong_tag_once ? a.tag + 1 : a.tag);
  faults_.audio_wrong_tag_once = false;
  sim_put_le32(status, 8, a.status);
  const std::size_t n = std::min(status.size(), data.size());
  std::memcpy(data.data(), status.data(), n);
  a.phase = Phase::IDLE;
  if (a.execute_pending) {
    // The firmware starts: the function drops off the bus now and comes back re-enumerated.
    a.execute_pending = false;
    a.running = !faults_.audio_back_as_bootloader;
    a.gone_ns = now_ns;
    a.back_ns.reset();
    if (!faults_.audio_no_reenumeration) a.back_ns = now_ns + config_.audio_reenumerate_delay_ns;
    ++a.generation;
    a.address.reset();
  }
  return {SimControlOutcome::OK, n};
}

}  // namespace orthoflow::simulation
