#include "drivers/kinect/kinect_motor.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "drivers/kinect/kinect_audio.hpp"
#include "drivers/kinect/kinect_protocol.hpp"
#include "drivers/kinect/kinect_siblings.hpp"

namespace orthoflow::drivers::kinect {

namespace {

struct LedName {
  LedMode mode;
  std::string_view name;
};
constexpr std::array<LedName, 6> LED_NAMES = {{{LedMode::OFF, "off"},
                                               {LedMode::GREEN, "green"},
                                               {LedMode::RED, "red"},
                                               {LedMode::YELLOW, "yellow"},
                                               {LedMode::BLINK_GREEN, "blink-green"},
                                               {LedMode::BLINK_RED_YELLOW, "blink-red-yellow"}}};

KinectError usb_failure(const UsbError& usb, std::uint8_t request = 0) noexcept {
  KinectError e;
  e.code = KinectError::Code::USB;
  e.usb = usb;
  e.opcode = request;
  return e;
}

KinectError refusal(UsbError::Code code, std::string_view why) noexcept {
  return usb_failure(UsbError{code, 0, why});
}

std::int16_t be16(std::span<const std::byte> bytes, std::size_t at) noexcept {
  const auto hi = std::to_integer<unsigned>(bytes[at]);
  const auto lo = std::to_integer<unsigned>(bytes[at + 1]);
  return static_cast<std::int16_t>(static_cast<std::uint16_t>((hi << 8) | lo));
}

TiltStatus tilt_status(std::uint8_t raw) noexcept {
  switch (raw) {
    case 0x00:
      return TiltStatus::STOPPED;
    case 0x01:
      return TiltStatus::AT_LIMIT;
    case 0x04:
      return TiltStatus::MOVING;
    default:
      return TiltStatus::UNKNOWN;
  }
}

// handle_events takes whole milliseconds: round the wait up so the loop never spins on a 0 ms
// wait (0 means "do not block").
UsbTimeout wait_for(std::int64_t ns) noexcept {
  return UsbTimeout{std::max<std::int64_t>(1, (ns + 999'999) / 1'000'000)};
}

}  // namespace

std::uint16_t encode_tilt(double degrees) noexcept {
  if (std::isnan(degrees)) return 0;
  const double clamped = std::clamp(degrees, -MOTOR_TILT_LIMIT_DEG, MOTOR_TILT_LIMIT_DEG);
  const auto half_degrees = static_cast<std::int16_t>(std::lround(clamped * 2.0));
  return static_cast<std::uint16_t>(half_degrees);
}

const char* to_string(LedMode mode) noexcept {
  for (const LedName& n : LED_NAMES) {
    if (n.mode == mode) return n.name.data();  // the literals are NUL-terminated
  }
  return "unknown";
}

std::optional<LedMode> parse_led_mode(std::string_view name) noexcept {
  for (const LedName& n : LED_NAMES) {
    if (n.name == name) return n.mode;
  }
  return std::nullopt;
}

const char* to_string(TiltStatus status) noexcept {
  switch (status) {
    case TiltStatus::STOPPED:
      return "stopped";
    case TiltStatus::AT_LIMIT:
      return "at_limit";
    case TiltStatus::MOVING:
      return "moving";
    case TiltStatus::UNKNOWN:
      return "unknown";
  }
  return "unknown";
}

std::optional<MotorState> decode_motor_state(std::span<const std::byte> reply) noexcept {
  if (reply.size() != MOTOR_STATE_BYTES) return std::nullopt;
  MotorState s;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    s.accel_counts[axis] = be16(reply, 2 + 2 * axis);
    s.accel_g[axis] = static_cast<double>(s.accel_counts[axis]) / ACCEL_COUNTS_PER_G;
    s.accel_mps2[axis] = s.accel_g[axis] * STANDARD_GRAVITY_MPS2;
  }
  s.tilt_raw = static_cast<std::int8_t>(std::to_integer<std::uint8_t>(reply[8]));
  if (s.tilt_raw != TILT_RAW_NO_READING) s.tilt_deg = static_cast<double>(s.tilt_raw) / 2.0;
  s.status_raw = std::to_integer<std::uint8_t>(reply[9]);
  s.status = tilt_status(s.status_raw);
  return s;
}

KinectMotor::KinectMotor(UsbTransport& transport, UsbDeviceHandle handle, const UsbDeviceInfo& info,
                         MotorOptions options) noexcept
    : transport_(&transport), handle_(std::move(handle)), info_(info), options_(options) {}

KinectMotor::KinectMotor(UsbTransport& transport, std::unique_ptr<AudioMotor> audio,
                         MotorOptions options) noexcept
    : transport_(&transport), info_(audio->info()), options_(options), audio_(std::move(audio)) {}

KinectMotor::~KinectMotor() = default;

void KinectMotor::count(const KinectError* failure) noexcept {
  if (failure == nullptr) {
    ++stats_.requests;
    return;
  }
  ++stats_.failures;
  if (failure->code == KinectError::Code::USB && failure->usb.code == UsbError::Code::TIMEOUT)
    ++stats_.timeouts;
  if (failure->code == KinectError::Code::BAD_REPLY) ++stats_.bad_replies;
}

Result<std::unique_ptr<KinectMotor>, KinectError> KinectMotor::open(UsbTransport& transport,
                                                                    const CameraInfo& camera,
                                                                    MotorOptions options) {
  if (options.transfer_timeout.count() <= 0 || options.poll_interval.count() <= 0)
    return err(refusal(UsbError::Code::INVALID_PARAM, "kinect motor: timeouts must be > 0"));
  if (camera.model != Model::K1414) {
    // NOT_SUPPORTED ("upload the audio firmware first") while the audio device is a bootloader.
    AudioMotorOptions audio_options;
    audio_options.reset_at_open = options.reset_audio_at_open;
    auto audio = AudioMotor::open(transport, camera, audio_options);
    if (!audio) return err(audio.error());
    return std::unique_ptr<KinectMotor>(
        new KinectMotor(transport, std::move(audio.value()), options));
  }
  auto found = transport.enumerate(VENDOR_MICROSOFT, PID_MOTOR);
  if (!found.has_value()) return err(usb_failure(found.error()));
  std::vector<const UsbDeviceInfo*> motors;
  for (const UsbDeviceInfo& d : found.value()) {
    if (d.product == PID_MOTOR) motors.push_back(&d);
  }
  const UsbDeviceInfo* motor = find_sibling(camera.usb, motors);
  if (motor == nullptr)
    return err(refusal(UsbError::Code::NOT_FOUND, "kinect motor: no 0x02B0 sibling of the camera"));
  auto opened = transport.open(*motor);
  if (!opened.has_value()) return err(usb_failure(opened.error()));
  UsbDeviceHandle handle = std::move(opened.value());
  // No kernel driver is known to bind the motor; detach one if a platform does.
  if (auto active = transport.kernel_driver_active(handle, 0); active.has_value() && *active) {
    if (auto d = transport.detach_kernel_driver(handle, 0); !d.has_value())
      return err(usb_failure(d.error()));
  }
  if (auto c = transport.claim_interface(handle, 0); !c.has_value())
    return err(usb_failure(c.error()));
  return std::unique_ptr<KinectMotor>(
      new KinectMotor(transport, std::move(handle), *motor, options));
}

Result<std::size_t, KinectError> KinectMotor::transfer(const UsbControlSetup& setup,
                                                       std::span<std::byte> data) {
  auto moved = transport_->control(handle_, setup, data, options_.transfer_timeout);
  if (!moved.has_value()) {
    ++stats_.failures;
    if (moved.error().code == UsbError::Code::TIMEOUT) ++stats_.timeouts;
    return err(usb_failure(moved.error(), setup.request));
  }
  ++stats_.requests;
  return moved.value();
}

Result<void, KinectError> KinectMotor::set_tilt(double degrees) {
  if (!std::isfinite(degrees) || std::abs(degrees) > MOTOR_TILT_LIMIT_DEG) {
    KinectError e;
    e.code = KinectError::Code::INVALID_ARGUMENT;
    e.opcode = MOTOR_SET_TILT.request;
    return err(e);
  }
  if (audio_) {
    auto done = audio_->set_tilt(degrees);
    count(done ? nullptr : &done.error());
    if (done) audio_target_ = static_cast<std::int32_t>(std::lround(degrees));
    return done;
  }
  UsbControlSetup setup = MOTOR_SET_TILT;
  setup.value = encode_tilt(degrees);
  if (auto sent = transfer(setup, {}); !sent.has_value()) return err(sent.error());
  return {};
}

Result<void, KinectError> KinectMotor::set_led(LedMode mode) {
  if (audio_) {
    auto done = audio_->set_led(mode);
    count(done ? nullptr : &done.error());
    return done;
  }
  UsbControlSetup setup = MOTOR_SET_LED;
  setup.value = static_cast<std::uint16_t>(mode);
  if (auto sent = transfer(setup, {}); !sent.has_value()) return err(sent.error());
  return {};
}

Result<MotorState, KinectError> KinectMotor::read_state() {
  if (audio_) {
    auto state = audio_->read_state();
    count(state ? nullptr : &state.error());
    if (!state) return err(state.error());
    return to_motor_state(state.value());
  }
  std::array<std::byte, MOTOR_STATE_BYTES> reply{};
  auto got = transfer(MOTOR_READ_STATE, reply);
  if (!got.has_value()) return err(got.error());
  auto maybe_state = decode_motor_state(std::span<const std::byte>(reply.data(), got.value()));
  if (!maybe_state) {
    ++stats_.bad_replies;
    KinectError e;
    e.code = KinectError::Code::BAD_REPLY;
    e.reply = ReplyCheck::TOO_SHORT;  // control IN never moves more than wLength
    e.opcode = MOTOR_READ_STATE.request;
    return err(e);
  }
  return *maybe_state;
}

Result<MotorState, KinectError> KinectMotor::wait_until_still(UsbTimeout timeout) {
  const MonotonicClock& clock = transport_->clock();
  const std::int64_t poll_ns = options_.poll_interval.count() * 1'000'000;
  const std::int64_t deadline =
      clock.now_ns() + std::max<std::int64_t>(0, timeout.count()) * 1'000'000;
  for (;;) {
    ++stats_.polls;
    auto state = read_state();
    if (!state.has_value()) return state;
    if (audio_) {
      if (!audio_target_) return state;
      if (state.value().tilt_deg == static_cast<double>(*audio_target_)) {
        state.value().status = TiltStatus::STOPPED;  // inferred: see the header
        return state;
      }
    } else if (state.value().status != TiltStatus::MOVING) {
      return state;
    }
    const std::int64_t now = clock.now_ns();
    if (now >= deadline)
      return err(usb_failure(UsbError{UsbError::Code::TIMEOUT, 0, "kinect motor wait_until_still"},
                             MOTOR_READ_STATE.request));
    // Pump, not sleep: iso callbacks of a running camera on this transport keep being served.
    const std::int64_t next = std::min(now + poll_ns, deadline);
    while (clock.now_ns() < next) {
      if (auto pumped = transport_->handle_events(wait_for(next - clock.now_ns()));
          !pumped.has_value())
        return err(usb_failure(pumped.error()));
    }
  }
}

}  // namespace orthoflow::drivers::kinect
