// LibusbTransport: device discovery. enumerate() and the lookup open() needs, both over one scan of
// libusb's device list. Part of the libusb implementation: one of the four files that include
// libusb's header.
#include "drivers/usb/libusb_transport.hpp"

#include "drivers/usb/libusb_api.hpp"

#include <algorithm>
#include <array>
#include <string_view>
#include <utility>

#include "drivers/usb/libusb_call.hpp"

namespace orthoflow::drivers {
namespace {

// Owns libusb's device list, and one reference per device, for the length of one scan.
class DeviceList {
 public:
  static Result<DeviceList, UsbError> get(libusb_context* context) {
    libusb_device** list = nullptr;
    auto count_result = libusb_call("libusb_get_device_list",
                                    [&] { return libusb_get_device_list(context, &list); });
    if (!count_result) return orthoflow::err(count_result.error());
    return DeviceList(list, static_cast<std::size_t>(*count_result));
  }
  DeviceList(DeviceList&& other) noexcept
      : list_(std::exchange(other.list_, nullptr)), count_(other.count_) {}
  DeviceList(const DeviceList&) = delete;
  DeviceList& operator=(const DeviceList&) = delete;
  DeviceList& operator=(DeviceList&&) = delete;
  ~DeviceList() {
    if (list_ != nullptr) libusb_free_device_list(list_, 1);
  }
  [[nodiscard]] std::span<libusb_device* const> devices() const noexcept { return {list_, count_}; }

 private:
  DeviceList(libusb_device** list, std::size_t count) noexcept : list_(list), count_(count) {}
  libusb_device** list_;
  std::size_t count_;
};

bool read_descriptor(libusb_device* device, libusb_device_descriptor& descriptor) {
  auto read_result = libusb_call("libusb_get_device_descriptor",
                                 [&] { return libusb_get_device_descriptor(device, &descriptor); });
  return read_result.has_value();
}

// Best effort: a serial needs an open handle, which permissions may refuse; then it stays empty.
void read_serial(libusb_device* device, std::uint8_t string_index, UsbDeviceInfo& info) {
  libusb_device_handle* handle = nullptr;
  if (!libusb_call("libusb_open", [&] { return libusb_open(device, &handle); })) return;
  std::array<unsigned char, USB_SERIAL_MAX_BYTES + 1> text{};
  auto length_result = libusb_call("libusb_get_string_descriptor_ascii", [&] {
    return libusb_get_string_descriptor_ascii(handle, string_index, text.data(),
                                              static_cast<int>(text.size()));
  });
  libusb_close(handle);
  if (!length_result) return;
  const auto length = std::min(static_cast<std::size_t>(*length_result), USB_SERIAL_MAX_BYTES);
  info.serial.assign(std::string_view(reinterpret_cast<const char*>(text.data()), length));
}

UsbDeviceInfo describe(libusb_device* device, const libusb_device_descriptor& descriptor) {
  UsbDeviceInfo info;
  info.bus = libusb_get_bus_number(device);
  info.address = libusb_get_device_address(device);
  info.vendor = descriptor.idVendor;
  info.product = descriptor.idProduct;
  info.bcd_device = descriptor.bcdDevice;
  auto depth_result = libusb_call("libusb_get_port_numbers", [&] {
    return libusb_get_port_numbers(device, info.port_path.data(),
                                   static_cast<int>(info.port_path.size()));
  });
  if (depth_result)
    info.port_depth = static_cast<std::uint8_t>(std::min<int>(*depth_result, USB_MAX_PORT_DEPTH));
  libusb_config_descriptor* config = nullptr;
  if (libusb_call("libusb_get_active_config_descriptor",
                  [&] { return libusb_get_active_config_descriptor(device, &config); })) {
    info.interface_count = config->bNumInterfaces;
    libusb_free_config_descriptor(config);
  }
  if (descriptor.iSerialNumber != 0) read_serial(device, descriptor.iSerialNumber, info);
  return info;
}

}  // namespace

Result<std::vector<UsbDeviceInfo>, UsbError> LibusbTransport::enumerate(
    std::uint16_t vendor, std::optional<std::uint16_t> product) {
  check_not_in_callback();
  auto list_result = DeviceList::get(context_);
  if (!list_result) return orthoflow::err(list_result.error());
  std::vector<UsbDeviceInfo> found;
  for (libusb_device* device : list_result->devices()) {
    libusb_device_descriptor descriptor{};
    if (!read_descriptor(device, descriptor) || descriptor.idVendor != vendor) continue;
    if (product.has_value() && descriptor.idProduct != *product) continue;
    found.push_back(describe(device, descriptor));
  }
  return found;
}

Result<libusb_device_handle*, UsbError> LibusbTransport::open_native(const UsbDeviceInfo& wanted) {
  auto list_result = DeviceList::get(context_);
  if (!list_result) return orthoflow::err(list_result.error());
  libusb_device* match = nullptr;
  for (libusb_device* device : list_result->devices()) {
    libusb_device_descriptor descriptor{};
    if (libusb_get_bus_number(device) != wanted.bus ||
        libusb_get_device_address(device) != wanted.address)
      continue;
    if (read_descriptor(device, descriptor) && descriptor.idVendor == wanted.vendor &&
        descriptor.idProduct == wanted.product) {
      match = device;
    }
  }
  // Not in the list: unplugged, or re-enumerated at another address (enumerate again).
  if (match == nullptr) return orthoflow::err(refused(UsbError::Code::NO_DEVICE, "open"));
  libusb_device_handle* native = nullptr;
  auto open_result = libusb_call("libusb_open", [&] { return libusb_open(match, &native); });
  if (!open_result) return orthoflow::err(open_result.error());
  return native;
}

}  // namespace orthoflow::drivers
