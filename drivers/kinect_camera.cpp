#include "drivers/kinect_camera.hpp"

#include <algorithm>
#include <cstring>
#include <mutex>

#include "drivers/kinect_depth.hpp"
#include "drivers/kinect_siblings.hpp"
#include "kernels/packed_depth.hpp"

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

void KinectCamera::on_packet(std::span<const std::byte> bytes, UsbPacketStatus status,
                             FrameAssembler& assembler) noexcept {
  if (status != UsbPacketStatus::COMPLETED) {
    ++local_.iso_errors;
    // NO_DEVICE is an unplug; a CANCELLED nobody asked for is how some platforms report one.
    if (status == UsbPacketStatus::NO_DEVICE || status == UsbPacketStatus::CANCELLED) lost_ = true;
    return;
  }
  assembler.push(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
                 transport_->clock().now_ns());
}

void decode_depth(const AssembledFrame& frame, const StreamGeometry& geometry, DepthFormat format,
                  std::span<std::uint16_t> raw, bool scalar) noexcept {
  const bool eleven = format == DepthFormat::BITS_11;
  if (eleven) {
    scalar ? kernels::unpack_11bit_scalar(frame.bytes, raw)
           : kernels::unpack_11bit(frame.bytes, raw);
  } else {
    scalar ? kernels::unpack_10bit_scalar(frame.bytes, raw)
           : kernels::unpack_10bit(frame.bytes, raw);
  }
  if (frame.complete) return;
  // Pixels whose bits fall in a missing packet hold marker bits: make them "no reading".
  for_each_hole_pixels(frame, geometry, eleven ? 11U : 10U, raw.size(), [&](PixelRange r) {
    std::fill(raw.begin() + static_cast<std::ptrdiff_t>(r.begin),
              raw.begin() + static_cast<std::ptrdiff_t>(r.end), RAW_NO_READING);
  });
}

void KinectCamera::on_frame(const AssembledFrame& frame) noexcept {
  const auto& g = assembler_->geometry();
  const std::size_t missing = g.packets - frame.packets_present;
  if (missing > options_.max_missing_packets) {
    ++local_.frames_dropped;
    return;
  }
  if (pending_) {  // the previous depth frame never found its colour frame
    ++local_.depth_unpaired;
    publish_depth();
  }
  DepthFrame& slot = slots_[back_];
  decode_depth(frame, g, options_.depth_format, slot.raw);
  if (!frame.complete) ++local_.frames_degraded;
  slot.device_ticks = frame.device_ticks;
  slot.host_ns = frame.host_ns;
  slot.number = frame.number;
  slot.missing_packets = static_cast<std::uint32_t>(missing);
  slot.complete = frame.complete;
  slot.has_colour = false;
  if (!colour_assembler_) {
    publish_depth();
    return;
  }
  if (pair_with_ring(slot)) {
    publish_depth();
  } else {
    pending_ = true;  // the colour frame may still be on its way: the next one decides
  }
}

namespace {
/// Signed difference of two device times, modulo 2^32: the two streams unwrap independently.
std::int64_t tick_gap(std::uint64_t a, std::uint64_t b) noexcept {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a - b));
}
}  // namespace

void KinectCamera::attach_colour(DepthFrame& slot, std::size_t ring_index) noexcept {
  ColourSlot& c = colour_ring_[ring_index];
  std::memcpy(slot.bayer.data(), c.bayer.data(), c.bayer.size());
  slot.has_colour = true;
  slot.colour_ticks = c.ticks;
  slot.colour_complete = c.complete;
  c.used = true;
  ++local_.frames_paired;
}

bool KinectCamera::pair_with_ring(DepthFrame& slot) noexcept {
  std::size_t best = colour_ring_.size();
  std::int64_t best_gap = options_.pair_tolerance_ticks + 1;
  for (std::size_t i = 0; i < colour_ring_.size(); ++i) {
    const ColourSlot& c = colour_ring_[i];
    if (!c.valid || c.used) continue;
    const std::int64_t gap = std::abs(tick_gap(c.ticks, slot.device_ticks));
    if (gap < best_gap) {
      best = i;
      best_gap = gap;
    }
  }
  if (best == colour_ring_.size()) return false;
  attach_colour(slot, best);
  return true;
}

void KinectCamera::on_colour(const AssembledFrame& frame) noexcept {
  const auto& g = colour_assembler_->geometry();
  if (g.packets - frame.packets_present > options_.max_missing_colour_packets) {
    ++local_.colour_dropped;
    return;
  }
  ColourSlot& c = colour_ring_[colour_next_];
  colour_next_ = (colour_next_ + 1) % colour_ring_.size();
  if (c.valid && !c.used) ++local_.colour_unpaired;
  std::memcpy(c.bayer.data(), frame.bytes.data(), c.bayer.size());
  c.ticks = frame.device_ticks;
  c.valid = true;
  c.used = false;
  c.complete = frame.complete;
  if (!pending_) return;
  DepthFrame& slot = slots_[back_];
  const std::int64_t gap = tick_gap(c.ticks, slot.device_ticks);
  if (std::abs(gap) <= options_.pair_tolerance_ticks) {
    attach_colour(slot, (colour_next_ + colour_ring_.size() - 1) % colour_ring_.size());
    publish_depth();
  } else if (gap > options_.pair_tolerance_ticks) {
    ++local_.depth_unpaired;  // colour moved past it: this depth frame has no partner
    publish_depth();
  }
}

void KinectCamera::reset_pairing() noexcept {
  if (pending_) {
    ++local_.depth_unpaired;
    publish_depth();
  }
  for (ColourSlot& c : colour_ring_) c.valid = false;
}

void KinectCamera::publish_depth() noexcept {
  pending_ = false;
  const DepthFrame& slot = slots_[back_];
  const std::uint8_t previous =
      state_.exchange(static_cast<std::uint8_t>(back_ | FRESH), std::memory_order_acq_rel);
  if ((previous & FRESH) != 0) ++local_.frames_overwritten;
  back_ = previous & 0x3U;
  ++local_.frames_delivered;
  local_.last_frame_host_ns = slot.host_ns;
}

const DepthFrame* KinectCamera::latest_depth() noexcept {
  if ((state_.load(std::memory_order_acquire) & FRESH) == 0) return nullptr;
  const std::uint8_t previous = state_.exchange(front_, std::memory_order_acq_rel);
  front_ = previous & 0x3U;
  return &slots_[front_];
}

CameraHealth KinectCamera::health() const noexcept {
  std::lock_guard<core::SpinLock> lock(health_lock_);
  return shared_;
}

void KinectCamera::publish_health() noexcept {
  local_.depth = assembler_->stats();
  if (colour_assembler_) local_.colour = colour_assembler_->stats();
  if (control_) local_.control = control_->stats();
  local_.streaming = streaming_;
  local_.device_lost = lost_;
  std::lock_guard<core::SpinLock> lock(health_lock_);
  shared_ = local_;
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
