#pragma once
/// @file
/// @brief UsbError: the recoverable-failure value every USB transport call returns (STYLE rules 9,
/// 10). It holds only a code, a number and a view, so building, copying and returning one never
/// allocates and it can be returned on the frame path (an iso completion, a control round trip of a
/// running stream).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>

namespace orthoflow::drivers {

/// @brief What went wrong in a USB transport call, the implementation's own code for it, and which
/// call.
/// @note A plain value: trivially copyable, no owning member, safe to copy across threads.
/// Deterministic: the same failure always gives the same three fields.
struct UsbError {
  /// @brief The kind of failure. The first thirteen mirror libusb's `LIBUSB_ERROR_*` codes one to
  /// one (usb_error_code_from_libusb() in libusb_call.hpp maps them); the rest are the transport's
  /// own.
  enum class Code : std::uint8_t {
    IO,             ///< input/output error (LIBUSB_ERROR_IO)
    INVALID_PARAM,  ///< an argument is out of range or inconsistent (LIBUSB_ERROR_INVALID_PARAM)
    ACCESS,         ///< insufficient permissions: a udev rule is missing (LIBUSB_ERROR_ACCESS)
    NO_DEVICE,      ///< no such device, it may have been unplugged (LIBUSB_ERROR_NO_DEVICE)
    NOT_FOUND,  ///< entity not found: interface, endpoint, driver, stream (LIBUSB_ERROR_NOT_FOUND)
    BUSY,       ///< resource busy: interface claimed elsewhere, stream running (LIBUSB_ERROR_BUSY)
    TIMEOUT,    ///< the operation timed out (LIBUSB_ERROR_TIMEOUT)
    OVERFLOW,   ///< the device sent more data than the buffer holds (LIBUSB_ERROR_OVERFLOW)
    PIPE,       ///< the endpoint stalled or the control request was refused (LIBUSB_ERROR_PIPE)
    INTERRUPTED,     ///< a signal interrupted the call, and every bounded retry too
                     ///< (LIBUSB_ERROR_INTERRUPTED)
    NO_MEM,          ///< out of memory (LIBUSB_ERROR_NO_MEM)
    NOT_SUPPORTED,   ///< not supported on this platform or by this transport
                     ///< (LIBUSB_ERROR_NOT_SUPPORTED)
    OTHER,           ///< any other native failure, including codes this build does not know
                     ///< (LIBUSB_ERROR_OTHER)
    SHORT_TRANSFER,  ///< an OUT transfer moved fewer bytes than it was given (native = the bytes
                     ///< moved)
    NOT_OPEN,        ///< the handle is empty, closed, or was opened by another transport
  };

  Code code = Code::OTHER;
  /// @brief The implementation's own code, kept for logs: a `LIBUSB_ERROR_*` value for libusb
  /// failures, the bytes moved for SHORT_TRANSFER, 0 when the transport itself refused the call.
  int native = 0;
  /// @brief The failing call, e.g. "libusb_claim_interface" or "start_iso".
  /// @pre Points at storage that outlives the error: always a string literal.
  std::string_view operation{};
};

static_assert(std::is_trivially_copyable_v<UsbError>, "UsbError must never own memory");

/// @brief Number of UsbError::Code enumerators (they are contiguous from 0).
/// @note Keep equal to the last enumerator + 1; the test iterates over all of them.
inline constexpr std::size_t USB_ERROR_CODE_COUNT =
    static_cast<std::size_t>(UsbError::Code::NOT_OPEN) + 1;

/// @brief The enumerator's name in lower case, e.g. "no_device"; "unknown" for a value outside the
/// enum.
/// @pre none. @note Never allocates; returns a string literal. Thread-safe and deterministic.
[[nodiscard]] const char* to_string(UsbError::Code code) noexcept;

/// @brief "<code> in <operation> (native <n>)", e.g. "no_device in libusb_open (native -4)".
/// @pre none. @note Allocates: call it off the frame path (logs, CLI). Thread-safe and
/// deterministic.
[[nodiscard]] std::string to_string(const UsbError& error);

}  // namespace orthoflow::drivers
