#pragma once
/// @file
/// @brief (internal) The one wrapper every libusb call of LibusbTransport goes through (STYLE rule
/// 10, after iceoryx's IOX_POSIX_CALL): bounded retries on LIBUSB_ERROR_INTERRUPTED, then the
/// native code is mapped to a UsbError. Also the mappings from libusb's codes and the
/// transfer-length check. Deliberately free of libusb's header, so the mappings are tested as plain
/// functions over ints; the values they map are libusb's documented, ABI-stable codes;
/// libusb_call.cpp defines them over libusb's header's own constants and static_asserts the one
/// constant this header names.
#include <cstddef>
#include <string_view>
#include <type_traits>

#include "core/result.hpp"
#include "drivers/usb/usb_error.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers {

/// @brief LIBUSB_ERROR_INTERRUPTED's value (libusb's header; checked there by a static_assert).
inline constexpr int LIBUSB_INTERRUPTED_NATIVE = -10;
/// @brief How many times one libusb call is attempted while signals keep interrupting it.
inline constexpr int LIBUSB_CALL_MAX_ATTEMPTS = 8;

/// @brief The UsbError::Code of a `LIBUSB_ERROR_*` value (IO -1 ... NOT_SUPPORTED -12, OTHER -99).
/// @pre native < 0. @return OTHER for any value libusb does not define (a newer libusb's code, or
/// >= 0).
/// @note Pure, thread-safe. Defined in libusb_transport.cpp, over libusb's header's own constants.
[[nodiscard]] UsbError::Code usb_error_code_from_libusb(int native) noexcept;

/// @brief The UsbPacketStatus of a `libusb_transfer_status` value (COMPLETED 0 ... OVERFLOW 6).
/// @pre none. @return ERROR for a value libusb does not define. @note Pure, thread-safe.
[[nodiscard]] UsbPacketStatus usb_packet_status_from_libusb(int native) noexcept;

/// @brief Calls @p call (a libusb call returning an int or ssize_t status) until it returns
/// anything but LIBUSB_ERROR_INTERRUPTED, at most LIBUSB_CALL_MAX_ATTEMPTS times.
/// @pre @p operation is a string literal naming the libusb function. @p call is safe to repeat
/// after an interruption: libusb's synchronous transfers restart interrupted event waits
/// themselves, so an INTERRUPTED reaching us comes from a call that moved no data (a poll, an open,
/// a submission).
/// @return the value (>= 0) on success, else the mapped UsbError with native = the libusb code.
/// @note Never allocates; thread-safety is that of @p call.
template <class Call>
[[nodiscard]] auto libusb_call(std::string_view operation, Call&& call)
    -> Result<std::invoke_result_t<Call&>, UsbError> {
  using Value = std::invoke_result_t<Call&>;
  static_assert(std::is_integral_v<Value> && std::is_signed_v<Value>,
                "libusb_call wraps calls returning a status");
  Value status = Value{LIBUSB_INTERRUPTED_NATIVE};
  for (int attempt = 0;
       attempt < LIBUSB_CALL_MAX_ATTEMPTS && status == Value{LIBUSB_INTERRUPTED_NATIVE};
       ++attempt) {
    status = call();
  }
  if (status >= 0) return status;
  const int native = static_cast<int>(status);
  return orthoflow::err(UsbError{usb_error_code_from_libusb(native), native, operation});
}

/// @brief An error the transport raises itself, before calling libusb (native 0).
/// @pre @p operation is a string literal. @note Pure, never allocates.
[[nodiscard]] constexpr UsbError refused(UsbError::Code code, std::string_view operation) noexcept {
  return UsbError{code, 0, operation};
}

/// @brief The outcome of a synchronous bulk or interrupt transfer: libusb's @p status and the bytes
/// it reports @p transferred, for a buffer of @p requested bytes moving OUT (@p is_out) or IN.
/// @pre none: a reported length outside [0, requested] is distrusted and clamped.
/// @return bytes moved; SHORT_TRANSFER (native = bytes moved) for a short OUT; the mapped error
/// otherwise.
/// @note Pure, never allocates. Defined in libusb_transport.cpp.
[[nodiscard]] Result<std::size_t, UsbError> finish_transfer(int status, int transferred,
                                                            std::size_t requested, bool is_out,
                                                            std::string_view operation) noexcept;

}  // namespace orthoflow::drivers
