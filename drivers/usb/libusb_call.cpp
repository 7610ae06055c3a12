// The mappings from libusb's codes to the seam's (declared in libusb_call.hpp), over libusb's
// header's own constants. Part of the libusb implementation: one of the four files that include
// libusb's header.
#include "drivers/usb/libusb_call.hpp"

#include "drivers/usb/libusb_api.hpp"

#include <algorithm>

// libusb_call() stops retrying on this one value; it must be libusb's.
static_assert(orthoflow::drivers::LIBUSB_INTERRUPTED_NATIVE == LIBUSB_ERROR_INTERRUPTED);

namespace orthoflow::drivers {

UsbError::Code usb_error_code_from_libusb(int native) noexcept {
  switch (native) {
    case LIBUSB_ERROR_IO:
      return UsbError::Code::IO;
    case LIBUSB_ERROR_INVALID_PARAM:
      return UsbError::Code::INVALID_PARAM;
    case LIBUSB_ERROR_ACCESS:
      return UsbError::Code::ACCESS;
    case LIBUSB_ERROR_NO_DEVICE:
      return UsbError::Code::NO_DEVICE;
    case LIBUSB_ERROR_NOT_FOUND:
      return UsbError::Code::NOT_FOUND;
    case LIBUSB_ERROR_BUSY:
      return UsbError::Code::BUSY;
    case LIBUSB_ERROR_TIMEOUT:
      return UsbError::Code::TIMEOUT;
    case LIBUSB_ERROR_OVERFLOW:
      return UsbError::Code::OVERFLOW;
    case LIBUSB_ERROR_PIPE:
      return UsbError::Code::PIPE;
    case LIBUSB_ERROR_INTERRUPTED:
      return UsbError::Code::INTERRUPTED;
    case LIBUSB_ERROR_NO_MEM:
      return UsbError::Code::NO_MEM;
    case LIBUSB_ERROR_NOT_SUPPORTED:
      return UsbError::Code::NOT_SUPPORTED;
    default:
      return UsbError::Code::OTHER;  // LIBUSB_ERROR_OTHER, and the codes of a newer libusb
  }
}

UsbPacketStatus usb_packet_status_from_libusb(int native) noexcept {
  switch (native) {
    case LIBUSB_TRANSFER_COMPLETED:
      return UsbPacketStatus::COMPLETED;
    case LIBUSB_TRANSFER_TIMED_OUT:
      return UsbPacketStatus::TIMED_OUT;
    case LIBUSB_TRANSFER_CANCELLED:
      return UsbPacketStatus::CANCELLED;
    case LIBUSB_TRANSFER_STALL:
      return UsbPacketStatus::STALL;
    case LIBUSB_TRANSFER_NO_DEVICE:
      return UsbPacketStatus::NO_DEVICE;
    case LIBUSB_TRANSFER_OVERFLOW:
      return UsbPacketStatus::OVERFLOW;
    default:
      return UsbPacketStatus::ERROR;  // LIBUSB_TRANSFER_ERROR, and unknown values
  }
}

Result<std::size_t, UsbError> finish_transfer(int status, int transferred, std::size_t requested,
                                              bool is_out, std::string_view operation) noexcept {
  if (status < 0)
    return orthoflow::err(UsbError{usb_error_code_from_libusb(status), status, operation});
  const std::size_t moved = std::min(static_cast<std::size_t>(std::max(transferred, 0)), requested);
  if (is_out && moved < requested) {
    return orthoflow::err(
        UsbError{UsbError::Code::SHORT_TRANSFER, static_cast<int>(moved), operation});
  }
  return moved;
}

}  // namespace orthoflow::drivers
