// LibusbTransport: the context, open devices, synchronous transfers and the event pump. The rest of
// the libusb implementation is libusb_discovery.cpp (enumerate, finding a device to open),
// libusb_iso.cpp (isochronous streams) and libusb_call.cpp (code mapping); only these four files
// include libusb's header (STYLE rule 16). Every libusb call that can fail goes through
// libusb_call(); the ones made without it cannot fail (getters, frees, libusb_close, libusb_exit).
#include "drivers/usb/libusb_transport.hpp"

#include "drivers/usb/libusb_api.hpp"

#include <algorithm>
#include <bitset>
#include <climits>
#include <string_view>
#include <utility>

#include "core/assert.hpp"
#include "drivers/usb/libusb_call.hpp"

namespace orthoflow::drivers {

struct LibusbOpenDevice {
  std::uint32_t id = 0;
  libusb_device_handle* handle = nullptr;
  std::bitset<256> claimed;  // interfaces to release on close
  std::bitset<256>
      detached;  // interfaces whose kernel driver is re-attached on close (KINECT_V1.md 2)
};

void LibusbOpenDeviceDeleter::operator()(LibusbOpenDevice* device) const noexcept { delete device; }

namespace {

Result<void, UsbError> as_void(const Result<int, UsbError>& result) {
  if (!result) return orthoflow::err(result.error());
  return {};
}

unsigned int libusb_timeout(UsbTimeout timeout) noexcept {
  return static_cast<unsigned int>(std::clamp<std::int64_t>(timeout.count(), 0, UINT_MAX));
}

template <class Call>
Result<int, UsbError> on_device(const LibusbOpenDevice* device, std::string_view operation,
                                Call&& call) {
  if (device == nullptr) return orthoflow::err(refused(UsbError::Code::NOT_OPEN, operation));
  return libusb_call(operation, [&] { return call(device->handle); });
}

Result<libusb_context*, UsbError> init_context() {
  libusb_context* context = nullptr;
  auto init_result = libusb_call("libusb_init", [&] { return libusb_init(&context); });
  if (!init_result) return orthoflow::err(init_result.error());
  return context;
}

}  // namespace

LibusbTransport::LibusbTransport(libusb_context* context, const MonotonicClock* clock) noexcept
    : context_(context), clock_(clock != nullptr ? clock : &steady_clock_) {}

LibusbTransport::~LibusbTransport() {
  OF_ASSERT(devices_.empty(),
            "LibusbTransport destroyed while a UsbDeviceHandle of it is still open");
  while (!devices_.empty()) close_device(devices_.back()->id);
  // A context with transfers still in flight must outlive them: then it is leaked, not exited.
  if (release_all_streams()) libusb_exit(context_);
}

Result<std::unique_ptr<LibusbTransport>, UsbError> LibusbTransport::create() {
  auto context_result = init_context();
  if (!context_result) return orthoflow::err(context_result.error());
  return std::unique_ptr<LibusbTransport>(new LibusbTransport(*context_result, nullptr));
}

Result<std::unique_ptr<LibusbTransport>, UsbError> LibusbTransport::create(
    const MonotonicClock& clock) {
  auto context_result = init_context();
  if (!context_result) return orthoflow::err(context_result.error());
  return std::unique_ptr<LibusbTransport>(new LibusbTransport(*context_result, &clock));
}

void LibusbTransport::check_not_in_callback() const noexcept {
  OF_ENFORCE(!in_callback_,
             "LibusbTransport called from an iso callback (libusb cannot nest event handling)");
}

LibusbOpenDevice* LibusbTransport::find_device(const UsbDeviceHandle& handle) const noexcept {
  if (handle.transport() != this) return nullptr;
  for (const auto& device : devices_) {
    if (device->id == handle.id()) return device.get();
  }
  return nullptr;
}

libusb_device_handle* LibusbTransport::native_handle(const UsbDeviceHandle& handle) const noexcept {
  const LibusbOpenDevice* device = find_device(handle);
  return device != nullptr ? device->handle : nullptr;
}

Result<UsbDeviceHandle, UsbError> LibusbTransport::open(const UsbDeviceInfo& wanted) {
  check_not_in_callback();
  auto native_result = open_native(wanted);
  if (!native_result) return orthoflow::err(native_result.error());
  OpenDevicePtr device(new LibusbOpenDevice());
  device->id = next_id_++;
  device->handle = *native_result;
  devices_.push_back(std::move(device));
  return make_handle(devices_.back()->id);
}

void LibusbTransport::close_device(std::uint32_t id) noexcept {
  check_not_in_callback();
  const auto it =
      std::find_if(devices_.begin(), devices_.end(), [id](const auto& d) { return d->id == id; });
  if (it == devices_.end()) return;
  // Streams first: libusb must not see the handle closed under transfers still in flight.
  stop_streams_of(id);
  LibusbOpenDevice& device = **it;
  for (std::size_t i = 0; i < device.claimed.size(); ++i) {
    const auto interface_number = static_cast<int>(i);
    if (device.claimed.test(i)) {
      (void)libusb_call("libusb_release_interface",
                        [&] { return libusb_release_interface(device.handle, interface_number); });
    }
    if (device.detached.test(i)) {
      (void)libusb_call("libusb_attach_kernel_driver", [&] {
        return libusb_attach_kernel_driver(device.handle, interface_number);
      });
    }
  }
  libusb_close(device.handle);
  devices_.erase(it);
}

Result<void, UsbError> LibusbTransport::claim_interface(const UsbDeviceHandle& handle,
                                                        std::uint8_t interface_number) {
  check_not_in_callback();
  LibusbOpenDevice* device = find_device(handle);
  auto claim_result = on_device(device, "libusb_claim_interface", [&](libusb_device_handle* h) {
    return libusb_claim_interface(h, interface_number);
  });
  if (claim_result) device->claimed.set(interface_number);
  return as_void(claim_result);
}

Result<void, UsbError> LibusbTransport::release_interface(const UsbDeviceHandle& handle,
                                                          std::uint8_t interface_number) {
  check_not_in_callback();
  LibusbOpenDevice* device = find_device(handle);
  auto release_result = on_device(device, "libusb_release_interface", [&](libusb_device_handle* h) {
    return libusb_release_interface(h, interface_number);
  });
  if (release_result) device->claimed.reset(interface_number);
  return as_void(release_result);
}

Result<void, UsbError> LibusbTransport::set_alt_setting(const UsbDeviceHandle& handle,
                                                        std::uint8_t interface_number,
                                                        std::uint8_t alt_setting) {
  check_not_in_callback();
  return as_void(on_device(
      find_device(handle), "libusb_set_interface_alt_setting", [&](libusb_device_handle* h) {
        return libusb_set_interface_alt_setting(h, interface_number, alt_setting);
      }));
}

Result<bool, UsbError> LibusbTransport::kernel_driver_active(const UsbDeviceHandle& handle,
                                                             std::uint8_t interface_number) {
  check_not_in_callback();
  auto active_result = on_device(
      find_device(handle), "libusb_kernel_driver_active",
      [&](libusb_device_handle* h) { return libusb_kernel_driver_active(h, interface_number); });
  if (!active_result) return orthoflow::err(active_result.error());
  return *active_result == 1;
}

Result<void, UsbError> LibusbTransport::detach_kernel_driver(const UsbDeviceHandle& handle,
                                                             std::uint8_t interface_number) {
  check_not_in_callback();
  LibusbOpenDevice* device = find_device(handle);
  auto detach_result = on_device(
      device, "libusb_detach_kernel_driver",
      [&](libusb_device_handle* h) { return libusb_detach_kernel_driver(h, interface_number); });
  if (detach_result) device->detached.set(interface_number);
  return as_void(detach_result);
}

Result<void, UsbError> LibusbTransport::attach_kernel_driver(const UsbDeviceHandle& handle,
                                                             std::uint8_t interface_number) {
  check_not_in_callback();
  LibusbOpenDevice* device = find_device(handle);
  auto attach_result = on_device(
      device, "libusb_attach_kernel_driver",
      [&](libusb_device_handle* h) { return libusb_attach_kernel_driver(h, interface_number); });
  if (attach_result) device->detached.reset(interface_number);
  return as_void(attach_result);
}

Result<void, UsbError> LibusbTransport::reset_device(const UsbDeviceHandle& handle) {
  check_not_in_callback();
  return as_void(on_device(find_device(handle), "libusb_reset_device",
                           [](libusb_device_handle* h) { return libusb_reset_device(h); }));
}

Result<void, UsbError> LibusbTransport::clear_halt(const UsbDeviceHandle& handle,
                                                   std::uint8_t endpoint) {
  check_not_in_callback();
  return as_void(on_device(find_device(handle), "libusb_clear_halt", [&](libusb_device_handle* h) {
    return libusb_clear_halt(h, endpoint);
  }));
}

Result<std::size_t, UsbError> LibusbTransport::control(const UsbDeviceHandle& handle,
                                                       const UsbControlSetup& setup,
                                                       std::span<std::byte> data,
                                                       UsbTimeout timeout) {
  check_not_in_callback();
  const LibusbOpenDevice* device = find_device(handle);
  if (device != nullptr && (data.size() > 0xFFFF || timeout.count() < 0)) {
    return orthoflow::err(refused(UsbError::Code::INVALID_PARAM, "libusb_control_transfer"));
  }
  auto length_result = on_device(device, "libusb_control_transfer", [&](libusb_device_handle* h) {
    return libusb_control_transfer(h, setup.request_type, setup.request, setup.value, setup.index,
                                   reinterpret_cast<unsigned char*>(data.data()),
                                   static_cast<std::uint16_t>(data.size()),
                                   libusb_timeout(timeout));
  });
  if (!length_result) return orthoflow::err(length_result.error());
  const bool is_out = (setup.request_type & LIBUSB_ENDPOINT_IN) == 0;
  return finish_transfer(0, *length_result, data.size(), is_out, "libusb_control_transfer");
}

Result<std::size_t, UsbError> LibusbTransport::bulk(const UsbDeviceHandle& handle,
                                                    std::uint8_t endpoint,
                                                    std::span<std::byte> data, UsbTimeout timeout) {
  return sync_transfer(handle, endpoint, data, timeout, true);
}

Result<std::size_t, UsbError> LibusbTransport::interrupt(const UsbDeviceHandle& handle,
                                                         std::uint8_t endpoint,
                                                         std::span<std::byte> data,
                                                         UsbTimeout timeout) {
  return sync_transfer(handle, endpoint, data, timeout, false);
}

Result<std::size_t, UsbError> LibusbTransport::sync_transfer(const UsbDeviceHandle& handle,
                                                             std::uint8_t endpoint,
                                                             std::span<std::byte> data,
                                                             UsbTimeout timeout, bool is_bulk) {
  check_not_in_callback();
  const std::string_view operation = is_bulk ? "libusb_bulk_transfer" : "libusb_interrupt_transfer";
  const LibusbOpenDevice* device = find_device(handle);
  if (device != nullptr && (data.size() > INT_MAX || timeout.count() < 0)) {
    return orthoflow::err(refused(UsbError::Code::INVALID_PARAM, operation));
  }
  auto* bytes = reinterpret_cast<unsigned char*>(data.data());
  const int length = static_cast<int>(data.size());
  int transferred = 0;
  auto status_result = on_device(device, operation, [&](libusb_device_handle* h) {
    transferred = 0;
    return is_bulk ? libusb_bulk_transfer(h, endpoint, bytes, length, &transferred,
                                          libusb_timeout(timeout))
                   : libusb_interrupt_transfer(h, endpoint, bytes, length, &transferred,
                                               libusb_timeout(timeout));
  });
  if (!status_result) return orthoflow::err(status_result.error());
  return finish_transfer(0, transferred, data.size(), (endpoint & LIBUSB_ENDPOINT_IN) == 0,
                         operation);
}

Result<std::size_t, UsbError> LibusbTransport::max_iso_packet_size(const UsbDeviceHandle& handle,
                                                                   std::uint8_t endpoint) {
  check_not_in_callback();
  auto size_result = on_device(
      find_device(handle), "libusb_get_max_iso_packet_size", [&](libusb_device_handle* h) {
        return libusb_get_max_iso_packet_size(libusb_get_device(h), endpoint);
      });
  if (!size_result) return orthoflow::err(size_result.error());
  return static_cast<std::size_t>(*size_result);
}

Result<void, UsbError> LibusbTransport::pump(UsbTimeout timeout, int* completed) noexcept {
  return as_void(libusb_call("libusb_handle_events_timeout_completed", [&] {
    timeval tv{};
    tv.tv_sec = static_cast<decltype(tv.tv_sec)>(timeout.count() / 1000);
    tv.tv_usec = static_cast<decltype(tv.tv_usec)>((timeout.count() % 1000) * 1000);
    return libusb_handle_events_timeout_completed(context_, &tv, completed);
  }));
}

Result<void, UsbError> LibusbTransport::handle_events(UsbTimeout timeout) {
  check_not_in_callback();
  if (timeout.count() < 0)
    return orthoflow::err(refused(UsbError::Code::INVALID_PARAM, "handle_events"));
  auto pump_result = pump(timeout, nullptr);
  collect_abandoned_streams();
  return pump_result;
}

}  // namespace orthoflow::drivers
