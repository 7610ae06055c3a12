#include "drivers/kinect/kinect_camera.hpp"

#include <algorithm>
#include <cstring>

#include "drivers/kinect/kinect_depth.hpp"
#include "drivers/kinect/kinect_siblings.hpp"

namespace orthoflow::drivers::kinect {

namespace {

constexpr std::uint16_t PID_AUDIO_K4W[] = {0x02BE, 0x02C3, 0x02BB};

bool is_audio(const UsbDeviceInfo& d) noexcept {
  if (d.product == PID_AUDIO) return true;
  return std::find(std::begin(PID_AUDIO_K4W), std::end(PID_AUDIO_K4W), d.product) !=
         std::end(PID_AUDIO_K4W);
}

KinectError usb_error(const UsbError& e) noexcept {
  KinectError k;
  k.code = KinectError::Code::USB;
  k.usb = e;
  return k;
}

bool all_zero_serial(std::string_view s) noexcept {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c == '0'; });
}

}  // namespace

Result<std::vector<CameraInfo>, KinectError> list_cameras(UsbTransport& transport) {
  auto found = transport.enumerate(VENDOR_MICROSOFT, std::nullopt);
  if (!found.has_value()) return err(usb_error(found.error()));
  std::vector<const UsbDeviceInfo*> motors, audios;
  for (const UsbDeviceInfo& d : found.value()) {
    if (d.product == PID_MOTOR) motors.push_back(&d);
    if (is_audio(d)) audios.push_back(&d);
  }
  std::vector<CameraInfo> cameras;
  for (const UsbDeviceInfo& d : found.value()) {
    const auto model = detect_model(d);
    if (!model) continue;
    CameraInfo info;
    info.usb = d;
    info.model = *model;
    info.serial = d.serial;
    if (*model == Model::K1414) info.has_motor = find_sibling(d, motors) != nullptr;
    if (all_zero_serial(d.serial.view()) || d.serial.view().empty()) {
      if (const UsbDeviceInfo* audio = find_sibling(d, audios)) info.serial = audio->serial;
    }
    cameras.push_back(info);
  }
  return cameras;
}

KinectCamera::KinectCamera(UsbTransport& transport, const CameraOptions& options)
    : transport_(&transport), options_(options), serial_(options.serial) {
  options_.serial = serial_;
  const unsigned bits = options.depth_format == DepthFormat::BITS_11 ? 11 : 10;
  assembler_ = std::make_unique<FrameAssembler>(depth_geometry(bits),
                                                [this](const AssembledFrame& f) { on_frame(f); });
  for (DepthFrame& slot : slots_) slot.raw.assign(DEPTH_PIXELS, RAW_NO_READING);
  if (options.colour) {
    colour_assembler_ = std::make_unique<FrameAssembler>(
        video_geometry(DEPTH_PIXELS), [this](const AssembledFrame& f) { on_colour(f); });
    for (DepthFrame& slot : slots_) slot.bayer.assign(DEPTH_PIXELS, 0);
    for (ColourSlot& c : colour_ring_) c.bayer.assign(DEPTH_PIXELS, 0);
  }
}

KinectCamera::~KinectCamera() {
  if (streaming_) (void)stop_depth();
}

Result<std::unique_ptr<KinectCamera>, KinectError> KinectCamera::open(
    UsbTransport& transport, const CameraOptions& options) {
  auto cameras = list_cameras(transport);
  if (!cameras.has_value()) return err(cameras.error());
  const CameraInfo* chosen = nullptr;
  for (const CameraInfo& c : cameras.value()) {
    if (options.serial.empty() || c.serial.view() == options.serial) {
      chosen = &c;
      break;
    }
  }
  if (chosen == nullptr) {
    KinectError e;
    e.code = KinectError::Code::NO_CAMERA;
    return err(e);
  }
  std::unique_ptr<KinectCamera> camera(new KinectCamera(transport, options));
  if (auto ok = camera->attach(*chosen); !ok.has_value()) return err(ok.error());
  camera->publish_health();
  return camera;
}

Result<void, KinectError> KinectCamera::attach(const CameraInfo& info) {
  auto opened = transport_->open(info.usb);
  if (!opened.has_value()) return err(usb_error(opened.error()));
  UsbDeviceHandle handle = std::move(opened.value());
  // gspca_kinect binds the camera on Linux: detach it (it is re-attached on close).
  if (auto active = transport_->kernel_driver_active(handle, 0);
      active.has_value() && active.value()) {
    if (auto d = transport_->detach_kernel_driver(handle, 0); !d.has_value())
      return err(usb_error(d.error()));
  }
  if (auto c = transport_->claim_interface(handle, 0); !c.has_value())
    return err(usb_error(c.error()));
  if (info.model == Model::K4W) {
    if (auto a = transport_->set_alt_setting(handle, 0, 1); !a.has_value())
      return err(usb_error(a.error()));
  }
  auto size = transport_->max_iso_packet_size(handle, EP_DEPTH);
  packet_size_ = size.has_value() && size.value() > 0 ? size.value() : ISO_PACKET_FALLBACK;
  handle_ = std::move(handle);
  control_ = std::make_unique<KinectControl>(*transport_, handle_, options_.control);
  auto cal = control_->read_calibration(info.model);
  if (!cal.has_value()) {
    control_.reset();
    transport_->close(handle_);
    return err(cal.error());
  }
  calibration_ = cal.value();
  info_ = info;
  return {};
}

Result<void, KinectError> KinectCamera::start_depth() {
  want_streaming_ = true;
  if (streaming_) return {};
  if (lost_ || !handle_.is_open()) {
    KinectError e;
    e.code = KinectError::Code::USB;
    e.usb.code = UsbError::Code::NO_DEVICE;
    e.usb.operation = "kinect start_depth";
    return err(e);
  }
  assembler_->reset();
  const UsbIsoConfig config{options_.iso_transfers, options_.iso_packets_per_transfer,
                            packet_size_};
  auto started = transport_->start_iso(
      handle_, EP_DEPTH, config,
      [this](std::span<const std::byte> bytes, std::size_t, UsbPacketStatus status) {
        on_packet(bytes, status, *assembler_);
      });
  if (!started.has_value()) return err(usb_error(started.error()));
  if (colour_assembler_) {
    colour_assembler_->reset();
    reset_pairing();
    auto colour = transport_->start_iso(
        handle_, EP_VIDEO, config,
        [this](std::span<const std::byte> bytes, std::size_t, UsbPacketStatus status) {
          on_packet(bytes, status, *colour_assembler_);
        });
    if (!colour.has_value()) {
      stop_transfers();
      return err(usb_error(colour.error()));
    }
  }
  // Transfers first, then the registers (KINECT_V1.md 5): no packet of the first frame is missed.
  auto script = control_->run(depth_start_script(options_.depth_format));
  if (script.has_value() && colour_assembler_)
    script = control_->run(video_start_script(VideoFormat::BAYER));
  if (!script.has_value()) {
    stop_transfers();
    return script;
  }
  streaming_ = true;
  stream_started_ns_ = transport_->clock().now_ns();
  publish_health();
  return {};
}

void KinectCamera::stop_transfers() noexcept {
  (void)transport_->stop_iso(handle_, EP_DEPTH);
  if (colour_assembler_) (void)transport_->stop_iso(handle_, EP_VIDEO);
}

Result<void, KinectError> KinectCamera::stop_depth() {
  want_streaming_ = false;
  if (!streaming_) return {};
  streaming_ = false;
  // Stop registers first, then cancel and drain (KINECT_V1.md 2.1).
  auto script = control_->run(depth_stop_script());
  if (colour_assembler_) {
    auto video = control_->run(video_stop_script());
    if (script.has_value()) script = video;
  }
  auto stopped = transport_->stop_iso(handle_, EP_DEPTH);
  if (colour_assembler_) {
    auto video = transport_->stop_iso(handle_, EP_VIDEO);
    if (stopped.has_value()) stopped = video;
  }
  publish_health();
  if (!script.has_value()) return script;
  if (!stopped.has_value()) return err(usb_error(stopped.error()));
  return {};
}

Result<void, KinectError> KinectCamera::restart_depth() {
  stop_transfers();
  streaming_ = false;
  return start_depth();
}

Result<void, KinectError> KinectCamera::try_reopen() {
  auto cameras = list_cameras(*transport_);
  if (!cameras.has_value()) return err(cameras.error());
  for (const CameraInfo& c : cameras.value()) {
    const bool same = info_.serial.view().empty() || all_zero_serial(info_.serial.view())
                          ? c.usb.bus == info_.usb.bus &&
                                std::equal(c.usb.ports().begin(), c.usb.ports().end(),
                                           info_.usb.ports().begin(), info_.usb.ports().end())
                          : c.serial.view() == info_.serial.view();
    if (!same) continue;
    if (auto ok = attach(c); !ok.has_value()) return ok;
    lost_ = false;
    ++local_.reopens;
    if (want_streaming_) return start_depth();
    return {};
  }
  KinectError e;
  e.code = KinectError::Code::NO_CAMERA;
  return err(e);
}

Result<void, KinectError> KinectCamera::pump(UsbTimeout timeout) {
  Result<void, KinectError> outcome{};
  auto events = transport_->handle_events(timeout);
  if (!events.has_value()) {
    if (events.error().code == UsbError::Code::NO_DEVICE) lost_ = true;
    outcome = err(usb_error(events.error()));
  }
  const std::int64_t now = transport_->clock().now_ns();
  if (lost_ && handle_.is_open()) {
    // The device went away: release what we hold; the frames in the assembler are abandoned.
    ++local_.unplugs;
    stop_transfers();
    control_.reset();
    transport_->close(handle_);
    assembler_->reset();
    if (colour_assembler_) {
      colour_assembler_->reset();
      reset_pairing();
    }
    streaming_ = false;
    next_reopen_ns_ = now + options_.reopen_interval_ns;
  } else if (lost_ && now >= next_reopen_ns_) {
    next_reopen_ns_ = now + options_.reopen_interval_ns;
    if (auto ok = try_reopen(); !ok.has_value() && ok.error().code != KinectError::Code::NO_CAMERA)
      outcome = ok;
  } else if (streaming_) {
    const std::int64_t last = std::max(local_.last_frame_host_ns, stream_started_ns_);
    if (now - last > options_.watchdog_ns) {
      ++local_.watchdog_restarts;
      if (auto ok = restart_depth(); !ok.has_value()) outcome = ok;
    }
  }
  publish_health();
  return outcome;
}

}  // namespace orthoflow::drivers::kinect
