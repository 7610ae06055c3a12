#include "drivers/usb/usb_error.hpp"

namespace orthoflow::drivers {

const char* to_string(UsbError::Code code) noexcept {
  switch (code) {
    case UsbError::Code::IO:
      return "io";
    case UsbError::Code::INVALID_PARAM:
      return "invalid_param";
    case UsbError::Code::ACCESS:
      return "access";
    case UsbError::Code::NO_DEVICE:
      return "no_device";
    case UsbError::Code::NOT_FOUND:
      return "not_found";
    case UsbError::Code::BUSY:
      return "busy";
    case UsbError::Code::TIMEOUT:
      return "timeout";
    case UsbError::Code::OVERFLOW:
      return "overflow";
    case UsbError::Code::PIPE:
      return "pipe";
    case UsbError::Code::INTERRUPTED:
      return "interrupted";
    case UsbError::Code::NO_MEM:
      return "no_mem";
    case UsbError::Code::NOT_SUPPORTED:
      return "not_supported";
    case UsbError::Code::OTHER:
      return "other";
    case UsbError::Code::SHORT_TRANSFER:
      return "short_transfer";
    case UsbError::Code::NOT_OPEN:
      return "not_open";
  }
  // Only reachable through a cast of an out-of-range value: name it rather than crash in a log
  // line.
  return "unknown";
}

std::string to_string(const UsbError& error) {
  std::string text = to_string(error.code);
  text += " in ";
  text += error.operation.empty() ? std::string_view("(unnamed call)") : error.operation;
  text += " (native ";
  text += std::to_string(error.native);
  text += ')';
  return text;
}

}  // namespace orthoflow::drivers
