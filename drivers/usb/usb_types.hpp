#pragma once
/// @file
/// @brief The plain values that cross the USB seam (usb_transport.hpp, which includes this file):
/// UsbDeviceInfo and the hub rule on it, the control setup, and the isochronous stream's packet
/// status, buffering, per-packet callback and health counters. No libusb type appears here.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

#include "core/assert.hpp"
#include "core/fixed_text.hpp"

namespace orthoflow::drivers {

/// @brief Deepest port path USB allows (7 tiers, USB 3.0 section 10.1.3).
inline constexpr std::size_t USB_MAX_PORT_DEPTH = 7;
/// @brief Longest serial number kept: a string descriptor holds at most 126 UTF-16 units.
inline constexpr std::size_t USB_SERIAL_MAX_BYTES = 126;

/// @brief One device found by enumerate(): where it sits on the bus and what it is.
/// @note A value type without heap memory; copy it across threads freely.
struct UsbDeviceInfo {
  std::uint8_t bus = 0;      ///< bus number
  std::uint8_t address = 0;  ///< device address on that bus (changes when the device re-enumerates)
  std::array<std::uint8_t, USB_MAX_PORT_DEPTH>
      port_path{};               ///< hub ports from the root, port_depth used
  std::uint8_t port_depth = 0;   ///< entries of port_path in use; 0 if the platform cannot tell
  std::uint16_t vendor = 0;      ///< idVendor, e.g. 0x045E (Microsoft), 0x22CD (Kinova)
  std::uint16_t product = 0;     ///< idProduct, e.g. 0x02AE (Kinect camera)
  std::uint16_t bcd_device = 0;  ///< bcdDevice: 0x010B marks a Kinect model 1414 camera
  std::uint8_t interface_count =
      0;  ///< bNumInterfaces of the active configuration; 0 if unreadable
  core::FixedText<USB_SERIAL_MAX_BYTES>
      serial{};  ///< iSerialNumber as ASCII; empty if none or unreadable

  /// @brief The used part of port_path. @pre port_depth <= USB_MAX_PORT_DEPTH. @note Views this
  /// object.
  [[nodiscard]] std::span<const std::uint8_t> ports() const noexcept {
    OF_ASSERT(port_depth <= USB_MAX_PORT_DEPTH, "UsbDeviceInfo: port_depth out of range");
    return {port_path.data(), port_depth};
  }
};

/// @brief True if @p a and @p b hang off the same hub port: same bus, same path but for the last
/// port. Used to match a Kinect's motor and audio functions to its camera (KINECT_V1.md 1).
/// @pre none. @note Pure; false when either path is unknown (depth 0).
[[nodiscard]] inline bool same_parent_hub(const UsbDeviceInfo& a, const UsbDeviceInfo& b) noexcept {
  if (a.bus != b.bus || a.port_depth == 0 || a.port_depth != b.port_depth) return false;
  const auto pa = a.ports();
  const auto pb = b.ports();
  return std::equal(pa.begin(), pa.end() - 1, pb.begin());
}

/// @brief The eight setup bytes of a control transfer but wLength, which is the buffer's size.
/// Bit 7 of request_type gives the direction (1 = IN, device to host).
struct UsbControlSetup {
  std::uint8_t request_type = 0;  ///< bmRequestType, e.g. 0x40 vendor OUT, 0xC0 vendor IN
  std::uint8_t request = 0;       ///< bRequest
  std::uint16_t value = 0;        ///< wValue, host byte order
  std::uint16_t index = 0;        ///< wIndex, host byte order
};

/// @brief How an isochronous packet (or its whole transfer) ended; mirrors libusb_transfer_status.
enum class UsbPacketStatus : std::uint8_t {
  COMPLETED,
  ERROR,
  TIMED_OUT,
  CANCELLED,
  STALL,
  NO_DEVICE,
  OVERFLOW
};

/// @brief Lower-case name, e.g. "no_device". @pre none. @note Never allocates; thread-safe.
[[nodiscard]] constexpr const char* to_string(UsbPacketStatus status) noexcept {
  switch (status) {
    case UsbPacketStatus::COMPLETED:
      return "completed";
    case UsbPacketStatus::ERROR:
      return "error";
    case UsbPacketStatus::TIMED_OUT:
      return "timed_out";
    case UsbPacketStatus::CANCELLED:
      return "cancelled";
    case UsbPacketStatus::STALL:
      return "stall";
    case UsbPacketStatus::NO_DEVICE:
      return "no_device";
    case UsbPacketStatus::OVERFLOW:
      return "overflow";
  }
  return "unknown";
}

/// @brief Buffering of one isochronous IN stream, fixed when it starts (Kinect on Linux: 16 x 16 x
/// 1920).
struct UsbIsoConfig {
  std::size_t transfers = 16;  ///< transfers kept in flight
  std::size_t packets_per_transfer =
      16;                          ///< iso packets per transfer (one per microframe at high speed)
  std::size_t packet_size = 1920;  ///< bytes reserved per packet: use max_iso_packet_size()
};

/// @brief Called once for every isochronous packet, in completion order.
/// - `bytes`: the packet's received bytes (bytes.size() == actual_length); empty unless status is
/// COMPLETED.
///   Valid only during the call: copy what you keep. Untrusted device data (STYLE rule 16).
/// - `actual_length`: bytes received, never more than the configured packet_size.
/// - `status`: the packet's status, or the whole transfer's when the transfer failed (NO_DEVICE on
/// unplug;
///   CANCELLED that stop_iso did not ask for means a disconnect on some platforms).
/// @note Runs on the transport's thread; must not call the transport or throw. Not called after
/// stop_iso().
using UsbIsoCallback = std::function<void(std::span<const std::byte> bytes,
                                          std::size_t actual_length, UsbPacketStatus status)>;

/// @brief Health counters of one isochronous stream (STYLE rule 16: every loss and retry is data).
struct UsbIsoStats {
  std::uint64_t transfers_completed = 0;  ///< transfers that came back COMPLETED
  std::uint64_t transfers_failed =
      0;  ///< transfers that came back with any other status (not stop_iso's)
  std::uint64_t packets_completed =
      0;  ///< packets delivered with status COMPLETED (empty ones included)
  std::uint64_t packets_failed = 0;  ///< packets delivered with any other status
  std::uint64_t bytes_received = 0;  ///< sum of actual_length over completed packets
  std::uint64_t resubmit_failures =
      0;  ///< transfers that could not be resubmitted and left the stream
  std::size_t transfers_in_flight = 0;  ///< transfers submitted now
};

}  // namespace orthoflow::drivers
