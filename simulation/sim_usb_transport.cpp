// SimUsbTransport: devices, handles, interfaces and control transfers. Iso streams and simulated
// time are in sim_usb_iso.cpp.
#include "simulation/sim_usb_transport.hpp"

#include <algorithm>
#include <climits>
#include <utility>

#include "core/assert.hpp"
#include "simulation/sim_usb_transport_state.hpp"

namespace orthoflow::simulation {

using drivers::UsbError;

namespace {

constexpr std::array<KinectFunction, 3> FUNCTIONS = {KinectFunction::CAMERA, KinectFunction::MOTOR,
                                                     KinectFunction::AUDIO};

Unexpected<UsbError> refused(UsbError::Code code, const char* operation) {
  return orthoflow::err(UsbError{code, 0, operation});
}

std::size_t function_index(KinectFunction f) noexcept { return static_cast<std::size_t>(f); }

}  // namespace

SimUsbTransport::SimUsbTransport(SimUsbTransportConfig config)
    : config_(config),
      owned_clock_(std::make_unique<drivers::ManualClock>(0)),
      clock_(owned_clock_.get()) {
  next_address_.fill(config_.first_address);
}

SimUsbTransport::SimUsbTransport(drivers::ManualClock& clock, SimUsbTransportConfig config)
    : config_(config), clock_(&clock) {
  next_address_.fill(config_.first_address);
}

SimUsbTransport::~SimUsbTransport() = default;

void SimUsbTransport::enforce_not_in_callback() const noexcept {
  OF_ENFORCE(!in_callback_, "SimUsbTransport: an iso callback must not call the transport");
}

void SimUsbTransport::assign_addresses(Slot& slot) {
  // Four addresses per Kinect: its internal hub, then camera, motor, audio (never reused).
  std::uint8_t& next = next_address_[slot.device->config().bus];
  OF_ENFORCE(next <= 123, "SimUsbTransport: the simulated bus ran out of addresses");
  slot.device->set_first_address(static_cast<std::uint8_t>(next + 1));
  next = static_cast<std::uint8_t>(next + 4);
}

void SimUsbTransport::refresh_audio(Slot& slot) {
  SimKinectDevice& d = *slot.device;
  if (!slot.present || d.audio_generation() == slot.audio_generation ||
      !d.present(KinectFunction::AUDIO, clock_->now_ns()))
    return;
  // Back from a re-enumeration: a new address, and the old claim is gone with the old device.
  std::uint8_t& next = next_address_[d.config().bus];
  OF_ENFORCE(next <= 125, "SimUsbTransport: the simulated bus ran out of addresses");
  d.set_audio_address(next);
  next = static_cast<std::uint8_t>(next + 1);
  slot.audio_generation = d.audio_generation();
  slot.claimed_by[function_index(KinectFunction::AUDIO)] = 0;
}

std::size_t SimUsbTransport::add_kinect(SimKinectConfig config) {
  enforce_not_in_callback();
  auto slot = std::make_unique<Slot>();
  slot->device = std::make_unique<SimKinectDevice>(std::move(config));
  slot->audio_generation = slot->device->audio_generation();
  assign_addresses(*slot);
  slots_.push_back(std::move(slot));
  return slots_.size() - 1;
}

SimKinectDevice& SimUsbTransport::kinect(std::size_t index) {
  OF_ENFORCE(index < slots_.size(), "SimUsbTransport::kinect: no such Kinect");
  return *slots_[index]->device;
}

bool SimUsbTransport::present(std::size_t index) const {
  OF_ENFORCE(index < slots_.size(), "SimUsbTransport::present: no such Kinect");
  return slots_[index]->present;
}

Result<std::vector<drivers::UsbDeviceInfo>, UsbError> SimUsbTransport::enumerate(
    std::uint16_t vendor, std::optional<std::uint16_t> product) {
  enforce_not_in_callback();
  run_until(clock_->now_ns());  // an unplug that is due shows here
  std::vector<drivers::UsbDeviceInfo> found;
  for (const auto& slot : slots_) {
    if (!slot->present) continue;
    refresh_audio(*slot);
    for (const KinectFunction f : FUNCTIONS) {
      if (!slot->device->present(f, clock_->now_ns())) continue;
      const drivers::UsbDeviceInfo info = slot->device->info(f);
      if (info.vendor == vendor && (!product || info.product == *product)) found.push_back(info);
    }
  }
  return found;
}

Result<drivers::UsbDeviceHandle, UsbError> SimUsbTransport::open(
    const drivers::UsbDeviceInfo& device) {
  enforce_not_in_callback();
  run_until(clock_->now_ns());
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    Slot& slot = *slots_[k];
    if (!slot.present) continue;
    refresh_audio(slot);
    for (const KinectFunction f : FUNCTIONS) {
      if (!slot.device->present(f, clock_->now_ns())) continue;
      const drivers::UsbDeviceInfo info = slot.device->info(f);
      if (info.bus != device.bus || info.address != device.address ||
          info.vendor != device.vendor || info.product != device.product)
        continue;
      auto h = std::make_unique<Handle>();
      h->id = next_handle_id_++;
      h->kinect = k;
      h->function = f;
      h->epoch = slot.epoch;
      h->audio_generation = slot.device->audio_generation();
      handles_.push_back(std::move(h));
      return make_handle(handles_.back()->id);
    }
  }
  return refused(UsbError::Code::NO_DEVICE, "open");
}

Result<SimUsbTransport::Handle*, UsbError> SimUsbTransport::lookup(
    const drivers::UsbDeviceHandle& handle, const char* operation, bool need_device) const {
  enforce_not_in_callback();
  if (handle.transport() != this) return refused(UsbError::Code::NOT_OPEN, operation);
  const auto it = std::find_if(handles_.begin(), handles_.end(),
                               [&](const auto& h) { return h->id == handle.id(); });
  if (it == handles_.end()) return refused(UsbError::Code::NOT_OPEN, operation);
  Handle* h = it->get();
  const Slot& slot = *slots_[h->kinect];
  if (need_device && (!slot.present || slot.epoch != h->epoch))
    return refused(UsbError::Code::NO_DEVICE, operation);
  if (need_device && h->function == KinectFunction::AUDIO &&
      (h->audio_generation != slot.device->audio_generation() ||
       !slot.device->present(KinectFunction::AUDIO, clock_->now_ns())))
    return refused(UsbError::Code::NO_DEVICE, operation);
  return h;
}

Result<SimUsbTransport::Handle*, UsbError> SimUsbTransport::interface_of(
    const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number,
    const char* operation) const {
  auto h_result = lookup(handle, operation, true);
  if (!h_result) return h_result;
  if (interface_number != 0) return refused(UsbError::Code::NOT_FOUND, operation);
  return h_result;
}

bool SimUsbTransport::streaming(const Handle& h) const noexcept {
  return std::any_of(streams_.begin(), streams_.end(),
                     [&](const auto& s) { return s->handle == h.id; });
}

Result<void, UsbError> SimUsbTransport::claim_interface(const drivers::UsbDeviceHandle& handle,
                                                        std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "claim_interface");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  Slot& slot = *slots_[h.kinect];
  std::uint32_t& owner = slot.claimed_by[function_index(h.function)];
  const bool kernel_holds = h.function == KinectFunction::CAMERA && slot.gspca_bound;
  if (h.claimed || owner != 0 || kernel_holds)
    return refused(UsbError::Code::BUSY, "claim_interface");
  owner = h.id;
  h.claimed = true;
  return {};
}

Result<void, UsbError> SimUsbTransport::release_interface(const drivers::UsbDeviceHandle& handle,
                                                          std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "release_interface");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  if (!h.claimed) return refused(UsbError::Code::NOT_FOUND, "release_interface");
  if (streaming(h)) return refused(UsbError::Code::BUSY, "release_interface");
  h.claimed = false;
  slots_[h.kinect]->claimed_by[function_index(h.function)] = 0;
  return {};
}

Result<void, UsbError> SimUsbTransport::set_alt_setting(const drivers::UsbDeviceHandle& handle,
                                                        std::uint8_t interface_number,
                                                        std::uint8_t alt_setting) {
  auto h_result = interface_of(handle, interface_number, "set_alt_setting");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  const bool k4w_camera =
      h.function == KinectFunction::CAMERA && slots_[h.kinect]->device->model() == KinectModel::K4W;
  if (!h.claimed || alt_setting > (k4w_camera ? 1 : 0))
    return refused(UsbError::Code::NOT_FOUND, "set_alt_setting");
  if (streaming(h)) return refused(UsbError::Code::BUSY, "set_alt_setting");
  h.alt = alt_setting;
  return {};
}

Result<bool, UsbError> SimUsbTransport::kernel_driver_active(const drivers::UsbDeviceHandle& handle,
                                                             std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "kernel_driver_active");
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  return h.function == KinectFunction::CAMERA && slots_[h.kinect]->gspca_bound;
}

Result<void, UsbError> SimUsbTransport::detach_kernel_driver(const drivers::UsbDeviceHandle& handle,
                                                             std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "detach_kernel_driver");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  Slot& slot = *slots_[h.kinect];
  if (h.function != KinectFunction::CAMERA || !slot.gspca_bound)
    return refused(UsbError::Code::NOT_FOUND, "detach_kernel_driver");
  slot.gspca_bound = false;
  h.detached = true;
  return {};
}

Result<void, UsbError> SimUsbTransport::attach_kernel_driver(const drivers::UsbDeviceHandle& handle,
                                                             std::uint8_t interface_number) {
  auto h_result = interface_of(handle, interface_number, "attach_kernel_driver");
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  Slot& slot = *slots_[h.kinect];
  if (h.function != KinectFunction::CAMERA)
    return refused(UsbError::Code::NOT_FOUND, "attach_kernel_driver");
  if (slot.gspca_bound || slot.claimed_by[function_index(h.function)] != 0)
    return refused(UsbError::Code::BUSY, "attach_kernel_driver");
  slot.gspca_bound = true;
  h.detached = false;
  return {};
}

Result<void, UsbError> SimUsbTransport::reset_device(const drivers::UsbDeviceHandle& handle) {
  auto h_result = lookup(handle, "reset_device", true);
  if (!h_result) return orthoflow::err(h_result.error());
  Handle& h = **h_result;
  if (streaming(h)) return refused(UsbError::Code::BUSY, "reset_device");
  // Same descriptors after the reset, so the handle stays valid (libusb's rule); the camera
  // forgets its registers and stops streaming.
  if (h.function == KinectFunction::CAMERA) slots_[h.kinect]->device->power_cycle();
  return {};
}

Result<void, UsbError> SimUsbTransport::clear_halt(const drivers::UsbDeviceHandle& handle,
                                                   std::uint8_t endpoint) {
  auto h_result = lookup(handle, "clear_halt", true);
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  const bool exists =
      endpoint == 0 ||
      (h.function == KinectFunction::CAMERA &&
       (endpoint == KINECT_VIDEO_ENDPOINT || endpoint == KINECT_DEPTH_ENDPOINT)) ||
      (h.function == KinectFunction::AUDIO && (endpoint == 0x01 || endpoint == 0x81));
  if (!exists) return refused(UsbError::Code::NOT_FOUND, "clear_halt");
  if (find_stream(h.id, endpoint) != nullptr) return refused(UsbError::Code::BUSY, "clear_halt");
  return {};
}

Result<std::size_t, UsbError> SimUsbTransport::control(const drivers::UsbDeviceHandle& handle,
                                                       const drivers::UsbControlSetup& setup,
                                                       std::span<std::byte> data,
                                                       drivers::UsbTimeout timeout) {
  auto h_result = lookup(handle, "control", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > 65535) return refused(UsbError::Code::INVALID_PARAM, "control");
  const Handle h = **h_result;  // a copy: callbacks cannot touch handles, but keep it simple
  run_until(clock_->now_ns());
  sync_streams(clock_->now_ns());
  Slot& slot = *slots_[h.kinect];
  if (!slot.present || slot.epoch != h.epoch) return refused(UsbError::Code::NO_DEVICE, "control");
  const SimControlReply reply = slot.device->control(h.function, setup, data, clock_->now_ns());
  if (reply.outcome == SimControlOutcome::TIMEOUT) {
    const auto wait = timeout.count() == 0 ? config_.infinite_wait : timeout;
    run_until(clock_->now_ns() + std::chrono::nanoseconds(wait).count());
    return refused(UsbError::Code::TIMEOUT, "control");
  }
  run_until(clock_->now_ns() + config_.control_latency.count());
  if (!slot.present || slot.epoch != h.epoch) return refused(UsbError::Code::NO_DEVICE, "control");
  if (reply.outcome == SimControlOutcome::PIPE) return refused(UsbError::Code::PIPE, "control");
  const bool out = (setup.request_type & 0x80U) == 0;
  if (out && reply.bytes < data.size())
    return orthoflow::err(
        UsbError{UsbError::Code::SHORT_TRANSFER, static_cast<int>(reply.bytes), "control"});
  return reply.bytes;
}

Result<std::size_t, UsbError> SimUsbTransport::bulk(const drivers::UsbDeviceHandle& handle,
                                                    std::uint8_t endpoint,
                                                    std::span<std::byte> data,
                                                    drivers::UsbTimeout timeout) {
  auto h_result = lookup(handle, "bulk", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > INT_MAX) return refused(UsbError::Code::INVALID_PARAM, "bulk");
  const Handle h = **h_result;
  const bool audio_bulk =
      h.function == KinectFunction::AUDIO && (endpoint == 0x01 || endpoint == 0x81);
  if (!audio_bulk || !h.claimed) return refused(UsbError::Code::NOT_FOUND, "bulk");
  run_until(clock_->now_ns());
  sync_streams(clock_->now_ns());
  Slot& slot = *slots_[h.kinect];
  const SimControlReply reply = slot.device->bulk(h.function, endpoint, data, clock_->now_ns());
  if (reply.outcome == SimControlOutcome::TIMEOUT) {
    const auto wait = timeout.count() == 0 ? config_.infinite_wait : timeout;
    run_until(clock_->now_ns() + std::chrono::nanoseconds(wait).count());
    return refused(UsbError::Code::TIMEOUT, "bulk");
  }
  run_until(clock_->now_ns() + config_.control_latency.count());
  if (!slot.present || slot.epoch != h.epoch) return refused(UsbError::Code::NO_DEVICE, "bulk");
  if (reply.outcome == SimControlOutcome::PIPE) return refused(UsbError::Code::PIPE, "bulk");
  return reply.bytes;
}

Result<std::size_t, UsbError> SimUsbTransport::interrupt(const drivers::UsbDeviceHandle& handle,
                                                         std::uint8_t, std::span<std::byte> data,
                                                         drivers::UsbTimeout) {
  auto h_result = lookup(handle, "interrupt", true);
  if (!h_result) return orthoflow::err(h_result.error());
  if (data.size() > INT_MAX) return refused(UsbError::Code::INVALID_PARAM, "interrupt");
  return refused(UsbError::Code::NOT_FOUND, "interrupt");
}

Result<std::size_t, UsbError> SimUsbTransport::max_iso_packet_size(
    const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint) {
  auto h_result = lookup(handle, "max_iso_packet_size", true);
  if (!h_result) return orthoflow::err(h_result.error());
  const Handle& h = **h_result;
  if (h.function == KinectFunction::CAMERA &&
      (endpoint == KINECT_VIDEO_ENDPOINT || endpoint == KINECT_DEPTH_ENDPOINT))
    return KINECT_ISO_MAX_PACKET_BYTES;
  if (h.function == KinectFunction::AUDIO && endpoint == 0x82) return std::size_t{524};
  return refused(UsbError::Code::NOT_FOUND, "max_iso_packet_size");
}

void SimUsbTransport::close_device(std::uint32_t id) noexcept {
  enforce_not_in_callback();
  const auto it =
      std::find_if(handles_.begin(), handles_.end(), [&](const auto& h) { return h->id == id; });
  if (it == handles_.end()) return;
  const Handle& h = **it;
  std::erase_if(streams_, [&](const auto& s) { return s->handle == id; });
  Slot& slot = *slots_[h.kinect];
  if (h.epoch == slot.epoch) {
    std::uint32_t& owner = slot.claimed_by[function_index(h.function)];
    if (owner == id) owner = 0;
    if (h.detached && slot.present) slot.gspca_bound = true;  // re-attached on close
  }
  handles_.erase(it);
}

}  // namespace orthoflow::simulation
