#pragma once
/// @file
/// @brief UsbTransport: the one narrow interface Kinect v1 and JACO protocol code talks to (STYLE
/// rule 16, USB_TESTING.md 3.1). No libusb type appears here, so protocol code compiles and is
/// tested without it.
/// The plain values it passes (UsbDeviceInfo, UsbControlSetup, the isochronous stream's types)
/// are in usb_types.hpp, included here.
///
/// Implementations:
/// - LibusbTransport (libusb_transport.hpp): real hardware. Its libusb_*.cpp files alone include
///   libusb's header (through libusb_api.hpp).
/// - simulation::SimUsbHost (simulation/devices/sim_usb_host.hpp): device simulators that implement
///   the documented protocols on simulated time (USB_TESTING.md 3.3), the Kinect and the JACO on
///   one host.
/// - simulation::ForwardingTransport (simulation/devices/forwarding_transport.hpp): the decorator
///   that forwards every call to another transport with a hook on each, for recording, replay and
///   tests (USB_TESTING.md 3.4).
/// What makes those possible:
/// - handles are opaque ids that each implementation maps to its own state (a decorator maps its
/// ids to
///   the handles of the transport it wraps);
/// - every call is a plain value in, a Result out: one record each for a recorder;
/// - isochronous data reaches the driver only through a callback run from handle_events(), which a
///   simulator or a replay may drive faster than real time;
/// - each transport carries its clock(): a simulator's clock is its simulated time.
///
/// Threading, for every implementation: a transport and its handles belong to one thread at a time
/// (the driver's USB thread). Iso callbacks run on that thread, inside handle_events() or inside a
/// synchronous call (control, bulk, interrupt, stop_iso) that pumps events while it waits. A
/// callback must not call back into the transport (OF_ENFORCE) and must not throw.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "core/fixed_text.hpp"
#include "core/result.hpp"
#include "drivers/usb/monotonic_clock.hpp"
#include "drivers/usb/usb_error.hpp"
#include "drivers/usb/usb_types.hpp"

namespace orthoflow::drivers {

class UsbTransport;

/// @brief An open device: a move-only token; its destructor closes the device (releasing claimed
/// interfaces, re-attaching detached kernel drivers and stopping its streams).
/// @note Belongs to its transport's thread. @pre Destroyed (or closed) before its transport.
class UsbDeviceHandle {
 public:
  /// @brief An empty handle: every transport call with it fails with NOT_OPEN. @pre none.
  UsbDeviceHandle() noexcept = default;
  /// @brief Takes over @p other's device; @p other becomes empty. @pre none.
  UsbDeviceHandle(UsbDeviceHandle&& other) noexcept : transport_(other.transport_), id_(other.id_) {
    other.transport_ = nullptr;
    other.id_ = 0;
  }
  /// @brief Closes the device held, then takes over @p other's. @pre none.
  UsbDeviceHandle& operator=(UsbDeviceHandle&& other) noexcept;
  UsbDeviceHandle(const UsbDeviceHandle&) = delete;
  UsbDeviceHandle& operator=(const UsbDeviceHandle&) = delete;
  /// @brief Closes the device, if any. @pre The transport is still alive.
  ~UsbDeviceHandle();

  /// @brief True until closed or moved from. @pre none.
  [[nodiscard]] bool is_open() const noexcept { return transport_ != nullptr; }
  /// @brief The transport-chosen id (never 0 while open; ids are not reused). @pre none.
  [[nodiscard]] std::uint32_t id() const noexcept { return id_; }
  /// @brief The transport that opened it, or nullptr. Implementations check it before using id().
  /// @pre none.
  [[nodiscard]] const UsbTransport* transport() const noexcept { return transport_; }

 private:
  friend class UsbTransport;
  UsbDeviceHandle(UsbTransport& transport, std::uint32_t id) noexcept
      : transport_(&transport), id_(id) {}
  void reset() noexcept;

  UsbTransport* transport_ = nullptr;
  std::uint32_t id_ = 0;
};

/// @brief A millisecond timeout; 0 means "wait forever" for transfers (libusb's rule), "do not
/// block" for handle_events(). Frame-path code always passes a finite timeout.
using UsbTimeout = std::chrono::milliseconds;

/// @brief The USB seam. Every operation returns a Result and never throws.
/// @note Not thread-safe: one thread at a time uses a transport and its handles (see the file
/// comment).
class UsbTransport {
 public:
  virtual ~UsbTransport() = default;
  UsbTransport(const UsbTransport&) = delete;
  UsbTransport& operator=(const UsbTransport&) = delete;

  /// @brief Devices present now with idVendor @p vendor and, if given, idProduct @p product (JACO
  /// matches on the vendor only). Reading a serial may briefly open the device; a failure leaves it
  /// empty.
  /// @pre none. @note Allocates; call at start-up or on re-plug, never on the frame path.
  [[nodiscard]] virtual Result<std::vector<UsbDeviceInfo>, UsbError> enumerate(
      std::uint16_t vendor, std::optional<std::uint16_t> product) = 0;
  /// @brief Opens the device @p device describes (matched by bus, address, vendor and product).
  /// @pre none. @return NO_DEVICE if it is no longer there, ACCESS without permission.
  [[nodiscard]] virtual Result<UsbDeviceHandle, UsbError> open(const UsbDeviceInfo& device) = 0;
  /// @brief Closes @p handle now (as its destructor would) and empties it. @pre none; empty is a
  /// no-op.
  void close(UsbDeviceHandle& handle) noexcept;

  /// @brief Claims interface @p interface_number (released again on close). @pre none.
  [[nodiscard]] virtual Result<void, UsbError> claim_interface(const UsbDeviceHandle& handle,
                                                               std::uint8_t interface_number) = 0;
  /// @brief Releases a claimed interface. @pre none.
  [[nodiscard]] virtual Result<void, UsbError> release_interface(const UsbDeviceHandle& handle,
                                                                 std::uint8_t interface_number) = 0;
  /// @brief Selects alternate setting @p alt_setting of a claimed interface (K4W camera: alt 1).
  /// @pre none.
  [[nodiscard]] virtual Result<void, UsbError> set_alt_setting(const UsbDeviceHandle& handle,
                                                               std::uint8_t interface_number,
                                                               std::uint8_t alt_setting) = 0;
  /// @brief True if a kernel driver (gspca_kinect) is bound to the interface. @pre none.
  /// @return NOT_SUPPORTED on platforms without kernel drivers to query.
  [[nodiscard]] virtual Result<bool, UsbError> kernel_driver_active(
      const UsbDeviceHandle& handle, std::uint8_t interface_number) = 0;
  /// @brief Unbinds the kernel driver from the interface; it is re-attached on close. @pre none.
  [[nodiscard]] virtual Result<void, UsbError> detach_kernel_driver(
      const UsbDeviceHandle& handle, std::uint8_t interface_number) = 0;
  /// @brief Re-binds a kernel driver detached before. @pre Its interfaces are released.
  [[nodiscard]] virtual Result<void, UsbError> attach_kernel_driver(
      const UsbDeviceHandle& handle, std::uint8_t interface_number) = 0;
  /// @brief Port-resets the device (Kinect audio at open). NOT_FOUND means it re-enumerated: close
  /// the handle, enumerate and open again. @pre No stream is running on it.
  [[nodiscard]] virtual Result<void, UsbError> reset_device(const UsbDeviceHandle& handle) = 0;
  /// @brief Clears a halt (stall) on @p endpoint. @pre No transfer is pending on it.
  [[nodiscard]] virtual Result<void, UsbError> clear_halt(const UsbDeviceHandle& handle,
                                                          std::uint8_t endpoint) = 0;

  /// @brief A control transfer on EP0 moving @p data (wLength = data.size()), IN or OUT by
  /// request_type.
  /// @pre data.size() <= 65535 (else INVALID_PARAM). @return bytes moved: for IN at most
  /// data.size(); an OUT moving fewer bytes than given is SHORT_TRANSFER. @note Blocks up to @p
  /// timeout; pumps events.
  [[nodiscard]] virtual Result<std::size_t, UsbError> control(const UsbDeviceHandle& handle,
                                                              const UsbControlSetup& setup,
                                                              std::span<std::byte> data,
                                                              UsbTimeout timeout) = 0;
  /// @brief A bulk transfer on @p endpoint (bit 7 set = IN) of @p data. @pre data.size() <=
  /// INT_MAX.
  /// @return bytes moved (short IN is success, short OUT is SHORT_TRANSFER). A timeout reports
  /// TIMEOUT even if part of the data moved. @note Blocks up to @p timeout; pumps events.
  [[nodiscard]] virtual Result<std::size_t, UsbError> bulk(const UsbDeviceHandle& handle,
                                                           std::uint8_t endpoint,
                                                           std::span<std::byte> data,
                                                           UsbTimeout timeout) = 0;
  /// @brief An interrupt transfer, same contract as bulk() (JACO: 64-byte packets on 0x02 / 0x82).
  [[nodiscard]] virtual Result<std::size_t, UsbError> interrupt(const UsbDeviceHandle& handle,
                                                                std::uint8_t endpoint,
                                                                std::span<std::byte> data,
                                                                UsbTimeout timeout) = 0;

  /// @brief Bytes @p endpoint moves per (micro)frame, transactions included (Kinect: 2 x 960 =
  /// 1920).
  /// @pre none. @return NOT_FOUND if the active configuration has no such endpoint.
  [[nodiscard]] virtual Result<std::size_t, UsbError> max_iso_packet_size(
      const UsbDeviceHandle& handle, std::uint8_t endpoint) = 0;
  /// @brief Starts streaming isochronous IN @p endpoint: allocates and submits config.transfers
  /// transfers and keeps resubmitting them as they complete; @p on_packet sees every packet. Submit
  /// first, then write the device's start registers (KINECT_V1.md 5). @pre An IN endpoint, every
  /// config field >= 1, a non-empty callback (else INVALID_PARAM). @return BUSY if the endpoint
  /// already streams.
  /// @note Allocates all buffers here, never later.
  [[nodiscard]] virtual Result<void, UsbError> start_iso(const UsbDeviceHandle& handle,
                                                         std::uint8_t endpoint,
                                                         const UsbIsoConfig& config,
                                                         UsbIsoCallback on_packet) = 0;
  /// @brief Stops the stream: no callback runs after this call begins; cancels every transfer and
  /// waits (pumping events, bounded) until all are back, then frees them. @pre none.
  /// @return NOT_FOUND if the endpoint does not stream; TIMEOUT if transfers never came back (then
  /// they are deliberately leaked, never freed under the host controller).
  [[nodiscard]] virtual Result<void, UsbError> stop_iso(const UsbDeviceHandle& handle,
                                                        std::uint8_t endpoint) = 0;
  /// @brief The stream's health counters. @pre none. @return NOT_FOUND if the endpoint does not
  /// stream.
  [[nodiscard]] virtual Result<UsbIsoStats, UsbError> iso_stats(const UsbDeviceHandle& handle,
                                                                std::uint8_t endpoint) const = 0;

  /// @brief The event pump: completes transfers and runs their callbacks, blocking up to @p timeout
  /// while nothing happens (0 = only what is pending). Never busy-polls. @pre timeout >= 0 (else
  /// INVALID_PARAM).
  [[nodiscard]] virtual Result<void, UsbError> handle_events(UsbTimeout timeout) = 0;

  /// @brief The clock protocol code must use for its own timeouts and watchdogs with this
  /// transport.
  /// @pre none. @note Thread-safe to read; outlives the transport's handles.
  [[nodiscard]] virtual const MonotonicClock& clock() const noexcept = 0;

 protected:
  UsbTransport() = default;
  /// @brief For implementations: a handle of this transport carrying @p id. @pre id != 0, not
  /// reused.
  [[nodiscard]] UsbDeviceHandle make_handle(std::uint32_t id) noexcept {
    return UsbDeviceHandle(*this, id);
  }
  /// @brief For implementations: releases everything device @p id holds. Unknown ids are ignored.
  /// @pre Not called from an iso callback.
  virtual void close_device(std::uint32_t id) noexcept = 0;

 private:
  friend class UsbDeviceHandle;
};

inline void UsbDeviceHandle::reset() noexcept {
  if (transport_ != nullptr) transport_->close_device(id_);
  transport_ = nullptr;
  id_ = 0;
}

inline UsbDeviceHandle& UsbDeviceHandle::operator=(UsbDeviceHandle&& other) noexcept {
  if (this != &other) {
    reset();
    transport_ = other.transport_;
    id_ = other.id_;
    other.transport_ = nullptr;
    other.id_ = 0;
  }
  return *this;
}

inline UsbDeviceHandle::~UsbDeviceHandle() { reset(); }

inline void UsbTransport::close(UsbDeviceHandle& handle) noexcept {
  // A handle of another transport is left alone: closing it here would reach into foreign state.
  if (handle.transport_ == this) handle.reset();
}

}  // namespace orthoflow::drivers
