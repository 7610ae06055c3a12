// SimKinectDevice: identity, the camera's EP0 command protocol (KINECT_V1.md 1, 4, 5) and the
// audio function's bootloader and firmware over bulk (KINECT_V1.md 12). The 1414 motor, the frame
// sources and the default scene are in sim_kinect_sources.cpp.
#include "simulation/sim_kinect_device.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "core/assert.hpp"

namespace orthoflow::simulation {

namespace {

constexpr std::uint8_t REQ_VENDOR_OUT = 0x40;
constexpr std::uint8_t REQ_VENDOR_IN = 0xC0;
constexpr std::size_t GM_HEADER_BYTES = 8;
constexpr std::size_t GM_MAX_PAYLOAD_BYTES = 1016;  // 0x400 - 8
constexpr std::uint16_t STATUS_OK = 0;
constexpr std::uint16_t STATUS_FAILED = 1;  // not a documented PrimeSense code: any nonzero value
constexpr std::uint16_t REG_VIDEO_MODE = 0x05;
constexpr std::uint16_t REG_DEPTH_MODE = 0x06;
constexpr std::uint16_t REG_COLOR_FORMAT = 0x0C;
constexpr std::uint16_t REG_DEPTH_FORMAT = 0x12;

// Camera, motor and audio at these ports of the internal hub and these address offsets.
constexpr std::uint8_t CAMERA_PORT = 1;
constexpr std::uint8_t AUDIO_PORT = 2;
constexpr std::uint8_t MOTOR_PORT = 3;

// Invented registration words (0x16 / 0x40) of the right order of magnitude; not a real device's.
constexpr std::array<std::int32_t, 29> DEFAULT_REGISTRATION = {
    33604, 0,  0,      0,     6826, -16192, 0,    0,    0,     6822, -4608, 2,     2, 1,   640,
    35,    36, -29812, -2270, 2366, -29846, 1117, 1120, -1127, 1128, 0,     -1131, 0, 1134};

void put_u16(std::span<std::uint8_t> out, std::size_t at, std::uint16_t v) noexcept {
  out[at] = static_cast<std::uint8_t>(v & 0xFFU);
  out[at + 1] = static_cast<std::uint8_t>(v >> 8);
}

void put_u32(std::span<std::uint8_t> out, std::size_t at, std::uint32_t v) noexcept {
  for (std::size_t i = 0; i < 4; ++i)
    out[at + i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFU);
}

std::uint16_t get_u16(std::span<const std::byte> in, std::size_t at) noexcept {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(in[at]) |
                                    (std::to_integer<unsigned>(in[at + 1]) << 8));
}

std::uint32_t get_u32(std::span<const std::byte> in, std::size_t at) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= std::to_integer<std::uint32_t>(in[at + i]) << (8 * i);
  return v;
}

void put_u32b(std::span<std::byte> out, std::size_t at, std::uint32_t v) noexcept {
  for (std::size_t i = 0; i < 4; ++i)
    out[at + i] = std::byte{static_cast<std::uint8_t>(v >> (8 * i))};
}

std::uint32_t get_u32(std::span<const std::uint8_t> in, std::size_t at) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= std::uint32_t{in[at + i]} << (8 * i);
  return v;
}

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

std::int64_t microframe_after(std::int64_t now_ns) noexcept {
  return now_ns / USB_MICROFRAME_NS + 1;
}

}  // namespace

SimKinectDevice::SimKinectDevice(SimKinectConfig config)
    : config_(std::move(config)),
      faults_(config_.faults),
      rng_(config_.fault_seed),
      depth_(0x70, [this](SimStreamMode m, std::uint64_t f,
                          std::span<std::uint8_t> p) { fill_frame(m, f, p); }),
      video_(0x80, [this](SimStreamMode m, std::uint64_t f, std::span<std::uint8_t> p) {
        fill_frame(m, f, p);
      }) {
  OF_ENFORCE(config_.model != KinectModel::K1414 || config_.serial.size() == 16,
             "SimKinectDevice: a model 1414 camera serial has 16 characters");
  OF_ENFORCE(!config_.hub_ports.empty() && config_.hub_ports.size() < drivers::USB_MAX_PORT_DEPTH,
             "SimKinectDevice: hub_ports needs 1..6 entries");
  OF_ENFORCE(config_.motor_slew_deg_per_s > 0.0, "SimKinectDevice: motor slew must be > 0");
  OF_ENFORCE(config_.audio_reenumerate_delay_ns >= 0, "SimKinectDevice: negative audio delay");
  audio_.running = config_.audio_firmware_running;
  scratch16_.assign(std::size_t{KINECT_FRAME_WIDTH} * KINECT_IR_HEIGHT, 0);
  writes_.reserve(1024);
}

bool SimKinectDevice::has_function(KinectFunction function) const noexcept {
  switch (function) {
    case KinectFunction::CAMERA:
      return true;
    case KinectFunction::MOTOR:
      return config_.model == KinectModel::K1414;
    case KinectFunction::AUDIO:
      return config_.with_audio;
  }
  return false;
}

drivers::UsbDeviceInfo SimKinectDevice::info(KinectFunction function) const noexcept {
  OF_ENFORCE(has_function(function), "SimKinectDevice::info: this model has no such function");
  drivers::UsbDeviceInfo d;
  d.bus = config_.bus;
  d.vendor = KINECT_VENDOR;
  d.interface_count = 1;
  std::copy(config_.hub_ports.begin(), config_.hub_ports.end(), d.port_path.begin());
  d.port_depth = static_cast<std::uint8_t>(config_.hub_ports.size() + 1);
  const bool k4w = config_.model == KinectModel::K4W;
  std::uint8_t port = CAMERA_PORT;
  switch (function) {
    case KinectFunction::CAMERA:
      d.address = first_address_;
      d.product = k4w ? KINECT_K4W_CAMERA_PID : KINECT_CAMERA_PID;
      d.bcd_device = config_.model == KinectModel::K1414 ? 0x010B : 0x010F;
      d.serial.assign(config_.model == KinectModel::K1414 ? std::string_view(config_.serial)
                                                          : std::string_view("0000000000000000"));
      break;
    case KinectFunction::MOTOR:
      port = MOTOR_PORT;
      d.address = static_cast<std::uint8_t>(first_address_ + 1);
      d.product = KINECT_MOTOR_PID;
      d.bcd_device = 0x0105;
      break;
    case KinectFunction::AUDIO:
      port = AUDIO_PORT;
      d.address = audio_.address.value_or(static_cast<std::uint8_t>(first_address_ + 2));
      d.product = k4w ? KINECT_K4W_AUDIO_PID : KINECT_AUDIO_PID;
      d.interface_count = audio_.running ? 2 : 1;
      d.bcd_device = 0x0100;
      d.serial.assign(config_.serial);
      break;
  }
  d.port_path[config_.hub_ports.size()] = port;
  return d;
}

void SimKinectDevice::power_cycle() noexcept {
  registers_.clear();
  cmos_registers_.clear();
  reply_pending_ = false;
  junk_left_ = 0;
  empty_left_ = 0;
  depth_.reset();
  video_.reset();
}

SimControlReply SimKinectDevice::control(KinectFunction function,
                                         const drivers::UsbControlSetup& setup,
                                         std::span<std::byte> data, std::int64_t now_ns) noexcept {
  if (faults_.control_stalls > 0) {
    --faults_.control_stalls;  // the request is lost: no effect on the device
    return {SimControlOutcome::TIMEOUT, 0};
  }
  switch (function) {
    case KinectFunction::CAMERA:
      return camera_control(setup, data, now_ns);
    case KinectFunction::MOTOR:
      return motor_control(setup, data, now_ns);
    case KinectFunction::AUDIO:
      break;  // bulk only (bulk())
  }
  return {SimControlOutcome::PIPE, 0};
}

// ---- Audio: bootloader and running firmware (KINECT_V1.md 12) -----------------------------------

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
  if (data.size() < 16 || get_u32(data, 0) != AUDIO_MAGIC) return {SimControlOutcome::PIPE, 0};
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
  a.tag = get_u32(data, 4);
  const std::uint32_t bytes = get_u32(data, 8);
  a.cmd = get_u32(data, 12);
  const std::uint32_t addr = get_u32(data, 16);
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
    if (c.size() < 24 || get_u32(c, 0) != AUDIO_IMAGE_MAGIC || get_u32(c, 12) != a.chunk_addr ||
        get_u32(c, 16) < 24) {
      a.status = AUDIO_BAD_HEADER;
    } else {
      a.have_header = true;
      a.base_addr = get_u32(c, 12);
      a.size = get_u32(c, 16);
      a.entry_addr = get_u32(c, 20);
    }
  }
  if (a.status == 0 && a.image.size() + a.chunk.size() > a.size) a.status = AUDIO_BAD_LENGTH;
  if (a.status == 0) a.image.insert(a.image.end(), a.chunk.begin(), a.chunk.end());
  a.commands.back().status = a.status;
}

void SimKinectDevice::firmware_command(std::span<const std::byte> data,
                                       std::int64_t now_ns) noexcept {
  Audio& a = audio_;
  a.tag = get_u32(data, 4);
  const std::uint32_t arg1 = get_u32(data, 8);
  a.cmd = get_u32(data, 12);
  const std::uint32_t arg2 = data.size() >= 20 ? get_u32(data, 16) : 0;
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
    // Gravity in the camera frame pitched by `angle` (no roll), as the 1414 model: Y up at level.
    const double rad = angle * 3.14159265358979323846 / 180.0;
    a.block.fill(std::byte{0});
    put_u32b(a.block, 16, 0);
    put_u32b(a.block, 20,
             static_cast<std::uint32_t>(
                 static_cast<std::int32_t>(std::lround(AUDIO_COUNTS_PER_G * std::cos(rad)))));
    put_u32b(a.block, 24,
             static_cast<std::uint32_t>(
                 static_cast<std::int32_t>(std::lround(AUDIO_COUNTS_PER_G * std::sin(rad)))));
    put_u32b(a.block, 28,
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
  put_u32b(status, 0, AUDIO_STATUS_MAGIC);
  put_u32b(status, 4, faults_.audio_wrong_tag_once ? a.tag + 1 : a.tag);
  faults_.audio_wrong_tag_once = false;
  put_u32b(status, 8, a.status);
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

SimControlReply SimKinectDevice::camera_control(const drivers::UsbControlSetup& setup,
                                                std::span<std::byte> data,
                                                std::int64_t now_ns) noexcept {
  if (setup.request != 0 || setup.value != 0 || setup.index != 0)
    return {SimControlOutcome::PIPE, 0};
  if (setup.request_type == REQ_VENDOR_IN) return read_reply(data);
  if (setup.request_type != REQ_VENDOR_OUT || !gm_command(data, now_ns))
    return {SimControlOutcome::PIPE, 0};
  return {SimControlOutcome::OK, data.size()};
}

SimControlReply SimKinectDevice::read_reply(std::span<std::byte> data) noexcept {
  if (reply_pending_ && junk_left_ > 0) {
    --junk_left_;
    const std::size_t n = std::min<std::size_t>(512, data.size());
    for (std::size_t i = 0; i < n; ++i) data[i] = std::byte{static_cast<std::uint8_t>(rng_.next())};
    if (n > 0) data[0] = std::byte{0xEE};  // never "RB"
    return {SimControlOutcome::OK, n};
  }
  if (reply_pending_ && empty_left_ > 0) {
    --empty_left_;
    return {SimControlOutcome::OK, 0};
  }
  if (!reply_pending_) return {SimControlOutcome::OK, 0};  // not ready: the host polls again
  const std::size_t n = std::min(reply_bytes_, data.size());
  if (n > 0) std::memcpy(data.data(), reply_.data(), n);
  reply_pending_ = false;
  return {SimControlOutcome::OK, n};
}

bool SimKinectDevice::gm_command(std::span<const std::byte> data, std::int64_t now_ns) noexcept {
  if (data.size() < GM_HEADER_BYTES || data[0] != std::byte{0x47} || data[1] != std::byte{0x4D})
    return false;
  const std::span<const std::byte> payload = data.subspan(GM_HEADER_BYTES);
  if (std::size_t{get_u16(data, 2)} * 2 != payload.size() || payload.size() > GM_MAX_PAYLOAD_BYTES)
    return false;
  ++commands_;
  const std::uint16_t cmd = get_u16(data, 4);
  const std::uint16_t tag = get_u16(data, 6);
  std::array<std::uint8_t, 512 - GM_HEADER_BYTES> out{};
  std::size_t n = 2;
  put_u16(out, 0, STATUS_FAILED);
  if (cmd == 0x02 && payload.size() >= 2) {  // GET_PARAM
    put_u16(out, 0, STATUS_OK);
    put_u16(out, 2, reg(get_u16(payload, 0)).value_or(0));
    n = 4;
  } else if (cmd == 0x03 && payload.size() >= 4) {  // SET_PARAM
    write_register(get_u16(payload, 0), get_u16(payload, 2), now_ns);
    put_u16(out, 0, STATUS_OK);
  } else if (cmd == 0x04) {  // GET_FIXED_PARAMS
    n = fixed_params(out);
  } else if (cmd == 0x16 && payload.size() >= 2) {  // ALGORITHM_PARAMS
    n = algorithm_params(get_u16(payload, 0), out);
  } else if (cmd == 0x95 && payload.size() >= 6) {  // CMOS register: bit 15 of reg = write
    const std::uint16_t r = get_u16(payload, 2);
    const auto address = static_cast<std::uint16_t>(r & 0x7FFFU);
    if ((r & 0x8000U) != 0) cmos_registers_[address] = get_u16(payload, 4);
    const auto it = cmos_registers_.find(address);
    put_u16(out, 0, STATUS_OK);
    put_u16(out, 2, address);
    put_u16(out, 4, it == cmos_registers_.end() ? 0 : it->second);
    n = 6;
  }
  answer(cmd, tag, std::span<const std::uint8_t>(out.data(), n), now_ns);
  return true;
}

void SimKinectDevice::answer(std::uint16_t cmd, std::uint16_t tag,
                             std::span<const std::uint8_t> payload, std::int64_t) noexcept {
  const std::span<std::uint8_t> r(reply_);
  r[0] = 0x52;
  r[1] = faults_.wrong_magic_once ? 0x43 : 0x42;
  put_u16(r, 2, static_cast<std::uint16_t>(payload.size() / 2));
  put_u16(r, 4, cmd);
  put_u16(r, 6, faults_.wrong_tag_once ? static_cast<std::uint16_t>(tag + 1) : tag);
  faults_.wrong_magic_once = false;
  faults_.wrong_tag_once = false;
  std::memcpy(reply_.data() + GM_HEADER_BYTES, payload.data(), payload.size());
  reply_bytes_ = GM_HEADER_BYTES + payload.size();
  reply_pending_ = true;
  junk_left_ = faults_.junk_replies;
  empty_left_ = faults_.empty_replies;
}

std::size_t SimKinectDevice::fixed_params(std::span<std::uint8_t> out) const noexcept {
  const std::size_t n = config_.model == KinectModel::K1414 ? 322 : 334;
  std::fill(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n), std::uint8_t{0});
  put_u16(out, 0, STATUS_OK);
  // 23 u32 fixed parameters precede the floats (meaning unknown; small invented values).
  for (std::size_t i = 0; i < 23; ++i) put_u32(out, 2 + 4 * i, static_cast<std::uint32_t>(i + 1));
  const float floats[4] = {static_cast<float>(config_.depth.emitter_dist_cm),
                           static_cast<float>(config_.calibration.dcmos_rcmos_dist_cm),
                           static_cast<float>(config_.depth.ref_dist_mm),
                           static_cast<float>(config_.depth.ref_pix_mm)};
  for (std::size_t i = 0; i < 4; ++i)
    put_u32(out, 94 + 4 * i, std::bit_cast<std::uint32_t>(floats[i]));
  return n;
}

std::size_t SimKinectDevice::algorithm_params(std::uint16_t param_id,
                                              std::span<std::uint8_t> out) const noexcept {
  const SimKinectCalibration& c = config_.calibration;
  put_u16(out, 0, STATUS_OK);
  if (param_id == 0x41) {  // pad info
    put_u16(out, 2, c.pad_start_lines);
    put_u16(out, 4, c.pad_end_lines);
    put_u16(out, 6, c.pad_cropping_lines);
    return 8;
  }
  if (param_id == 0x40) {  // registration table coefficients
    const bool unset = std::all_of(c.registration.begin(), c.registration.end(),
                                   [](std::int32_t v) { return v == 0; });
    const auto& words = unset ? DEFAULT_REGISTRATION : c.registration;
    for (std::size_t i = 0; i < words.size(); ++i)
      put_u32(out, 2 + 4 * i, static_cast<std::uint32_t>(words[i]));
    return 118;
  }
  if (param_id == 0x00) {  // const shift
    put_u16(out, 2, static_cast<std::uint16_t>(config_.depth.const_shift + 0.5));
    return 4;
  }
  put_u16(out, 0, STATUS_FAILED);
  return 2;
}

std::optional<std::uint16_t> SimKinectDevice::reg(std::uint16_t address) const {
  const auto it = registers_.find(address);
  if (it == registers_.end()) return std::nullopt;
  return it->second;
}

void SimKinectDevice::write_register(std::uint16_t address, std::uint16_t value,
                                     std::int64_t now_ns) noexcept {
  registers_[address] = value;
  writes_.emplace_back(address, value);
  const std::int64_t mf = microframe_after(now_ns);
  if (address == REG_DEPTH_MODE) {
    const std::uint16_t format = reg(REG_DEPTH_FORMAT).value_or(0);
    const SimStreamMode mode = format == 3   ? SimStreamMode::DEPTH_11BIT
                               : format == 2 ? SimStreamMode::DEPTH_10BIT
                                             : SimStreamMode::OFF;
    if (value == 2 && mode != SimStreamMode::OFF) {
      if (!config_.depth_source) ensure_default_scene();
      depth_.start(mode, mf);
    } else {
      depth_.stop(mf);
    }
  } else if (address == REG_VIDEO_MODE) {
    // UYVY (reg 0x0C = 5) is not simulated: such a start sends nothing.
    const bool bayer = value == 1 && reg(REG_COLOR_FORMAT).value_or(0) == 0;
    if (bayer || value == 3) {
      if (!config_.bayer_source || !config_.ir_source) ensure_default_scene();
      video_.start(bayer ? SimStreamMode::BAYER : SimStreamMode::IR_10BIT, mf);
    } else {
      video_.stop(mf);
    }
  }
}

std::size_t SimKinectDevice::iso_packet(std::uint8_t endpoint, std::int64_t microframe,
                                        std::span<std::byte> out) noexcept {
  if (endpoint == KINECT_DEPTH_ENDPOINT)
    return depth_.packet(microframe, faults_.packets, rng_, out);
  if (endpoint == KINECT_VIDEO_ENDPOINT)
    return video_.packet(microframe, faults_.packets, rng_, out);
  return 0;
}

}  // namespace orthoflow::simulation
