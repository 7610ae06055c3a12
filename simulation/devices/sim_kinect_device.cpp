// SimKinectDevice: identity, power, the control dispatch and the camera's EP0 command protocol
// (KINECT_V1.md 1, 4, 5). The audio function (bulk, KINECT_V1.md 12): sim_kinect_audio.cpp; the
// 1414 motor, the stream registers, the iso packets and the frame sources: sim_kinect_sources.cpp.
#include "simulation/devices/sim_kinect_device.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

#include "core/assert.hpp"
#include "simulation/devices/sim_bytes.hpp"

namespace orthoflow::simulation {

namespace {

constexpr std::uint8_t REQ_VENDOR_OUT = 0x40;
constexpr std::uint8_t REQ_VENDOR_IN = 0xC0;
constexpr std::size_t GM_HEADER_BYTES = 8;
constexpr std::size_t GM_MAX_PAYLOAD_BYTES = 1016;  // 0x400 - 8
constexpr std::uint16_t STATUS_OK = 0;
constexpr std::uint16_t STATUS_FAILED = 1;  // not a documented PrimeSense code: any nonzero value

// Camera, motor and audio at these ports of the internal hub and these address offsets.
constexpr std::uint8_t CAMERA_PORT = 1;
constexpr std::uint8_t AUDIO_PORT = 2;
constexpr std::uint8_t MOTOR_PORT = 3;

// Invented registration words (0x16 / 0x40) of the right order of magnitude; not a real device's.
constexpr std::array<std::int32_t, 29> DEFAULT_REGISTRATION = {
    33604, 0,  0,      0,     6826, -16192, 0,    0,    0,     6822, -4608, 2,     2, 1,   640,
    35,    36, -29812, -2270, 2366, -29846, 1117, 1120, -1127, 1128, 0,     -1131, 0, 1134};

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
  if (std::size_t{sim_get_le16(data, 2)} * 2 != payload.size() ||
      payload.size() > GM_MAX_PAYLOAD_BYTES)
    return false;
  ++commands_;
  const std::uint16_t cmd = sim_get_le16(data, 4);
  const std::uint16_t tag = sim_get_le16(data, 6);
  std::array<std::uint8_t, 512 - GM_HEADER_BYTES> out{};
  std::size_t n = 2;
  sim_put_le16(out, 0, STATUS_FAILED);
  if (cmd == 0x02 && payload.size() >= 2) {  // GET_PARAM
    sim_put_le16(out, 0, STATUS_OK);
    sim_put_le16(out, 2, reg(sim_get_le16(payload, 0)).value_or(0));
    n = 4;
  } else if (cmd == 0x03 && payload.size() >= 4) {  // SET_PARAM
    write_register(sim_get_le16(payload, 0), sim_get_le16(payload, 2), now_ns);
    sim_put_le16(out, 0, STATUS_OK);
  } else if (cmd == 0x04) {  // GET_FIXED_PARAMS
    n = fixed_params(out);
  } else if (cmd == 0x16 && payload.size() >= 2) {  // ALGORITHM_PARAMS
    n = algorithm_params(sim_get_le16(payload, 0), out);
  } else if (cmd == 0x95 && payload.size() >= 6) {  // CMOS register: bit 15 of reg = write
    const std::uint16_t r = sim_get_le16(payload, 2);
    const auto address = static_cast<std::uint16_t>(r & 0x7FFFU);
    if ((r & 0x8000U) != 0) cmos_registers_[address] = sim_get_le16(payload, 4);
    const auto it = cmos_registers_.find(address);
    sim_put_le16(out, 0, STATUS_OK);
    sim_put_le16(out, 2, address);
    sim_put_le16(out, 4, it == cmos_registers_.end() ? 0 : it->second);
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
  sim_put_le16(r, 2, static_cast<std::uint16_t>(payload.size() / 2));
  sim_put_le16(r, 4, cmd);
  sim_put_le16(r, 6, faults_.wrong_tag_once ? static_cast<std::uint16_t>(tag + 1) : tag);
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
  sim_put_le16(out, 0, STATUS_OK);
  // 23 u32 fixed parameters precede the floats (meaning unknown; small invented values).
  for (std::size_t i = 0; i < 23; ++i)
    sim_put_le32(out, 2 + 4 * i, static_cast<std::uint32_t>(i + 1));
  const float floats[4] = {static_cast<float>(config_.depth.emitter_dist_cm),
                           static_cast<float>(config_.calibration.dcmos_rcmos_dist_cm),
                           static_cast<float>(config_.depth.ref_dist_mm),
                           static_cast<float>(config_.depth.ref_pix_mm)};
  for (std::size_t i = 0; i < 4; ++i)
    sim_put_le32(out, 94 + 4 * i, std::bit_cast<std::uint32_t>(floats[i]));
  return n;
}

std::size_t SimKinectDevice::algorithm_params(std::uint16_t param_id,
                                              std::span<std::uint8_t> out) const noexcept {
  const SimKinectCalibration& c = config_.calibration;
  sim_put_le16(out, 0, STATUS_OK);
  if (param_id == 0x41) {  // pad info
    sim_put_le16(out, 2, c.pad_start_lines);
    sim_put_le16(out, 4, c.pad_end_lines);
    sim_put_le16(out, 6, c.pad_cropping_lines);
    return 8;
  }
  if (param_id == 0x40) {  // registration table coefficients
    const bool unset = std::all_of(c.registration.begin(), c.registration.end(),
                                   [](std::int32_t v) { return v == 0; });
    const auto& words = unset ? DEFAULT_REGISTRATION : c.registration;
    for (std::size_t i = 0; i < words.size(); ++i)
      sim_put_le32(out, 2 + 4 * i, static_cast<std::uint32_t>(words[i]));
    return 118;
  }
  if (param_id == 0x00) {  // const shift
    sim_put_le16(out, 2, static_cast<std::uint16_t>(config_.depth.const_shift + 0.5));
    return 4;
  }
  sim_put_le16(out, 0, STATUS_FAILED);
  return 2;
}

std::optional<std::uint16_t> SimKinectDevice::reg(std::uint16_t address) const {
  const auto it = registers_.find(address);
  if (it == registers_.end()) return std::nullopt;
  return it->second;
}

}  // namespace orthoflow::simulation
