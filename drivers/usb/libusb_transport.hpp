#pragma once
/// @file
/// @brief LibusbTransport: UsbTransport over libusb-1.0, for real devices (STYLE rule 16).
/// libusb's header is included only by its implementation files: libusb_transport.cpp (open
/// devices, synchronous transfers, the event pump), libusb_discovery.cpp (enumeration),
/// libusb_iso.cpp (isochronous streams) and libusb_call.cpp (code mapping); this header only
/// declares two libusb types. Every libusb call goes through libusb_call() (libusb_call.hpp).
/// Isochronous streams use libusb's asynchronous transfers, resubmitted from their completion
/// callback and driven by handle_events(); nothing busy-polls.
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/result.hpp"
#include "drivers/usb/monotonic_clock.hpp"
#include "drivers/usb/usb_error.hpp"
#include "drivers/usb/usb_transport.hpp"

struct libusb_context;
struct libusb_device_handle;

namespace orthoflow::drivers {

struct LibusbOpenDevice;  // defined in libusb_transport.cpp
struct LibusbIsoStream;   // defined in libusb_iso.cpp

/// @brief (internal) Deletes a LibusbOpenDevice; defined beside the type so other files need not
/// see it.
/// @pre The device's handle is already closed. @note Thread safety: that of LibusbTransport.
struct LibusbOpenDeviceDeleter {
  void operator()(LibusbOpenDevice* device) const noexcept;
};
/// @brief (internal) Deletes a LibusbIsoStream and frees its transfers; defined beside the type.
/// @pre None of its transfers is in flight. @note Thread safety: that of LibusbTransport.
struct LibusbIsoStreamDeleter {
  void operator()(LibusbIsoStream* stream) const noexcept;
};

/// @brief The libusb transport: one libusb context, the devices opened through it and their
/// streams.
/// @note Not thread-safe (UsbTransport's rule): one thread at a time. Movable by its unique_ptr
/// only. Deterministic only as far as the devices are.
class LibusbTransport final : public UsbTransport {
 public:
  /// @brief Initialises a private libusb context; its clock is a SteadyClock.
  /// @pre none. @return the libusb_init error (e.g. ACCESS, NO_MEM, OTHER) if libusb cannot start.
  /// On a machine without USB, libusb_init may also succeed and enumerate() then finds nothing.
  [[nodiscard]] static Result<std::unique_ptr<LibusbTransport>, UsbError> create();
  /// @brief As create(), with @p clock as the transport's clock().
  /// @pre @p clock outlives the transport.
  [[nodiscard]] static Result<std::unique_ptr<LibusbTransport>, UsbError> create(
      const MonotonicClock& clock);

  /// @brief Stops every stream, closes every device still open, then exits the libusb context.
  /// @pre No UsbDeviceHandle of this transport is still alive (OF_ASSERT): they would close a dead
  /// transport. Transfers that never came back from cancellation are leaked (with the context),
  /// never freed.
  ~LibusbTransport() override;

  /// @copydoc UsbTransport::enumerate
  [[nodiscard]] Result<std::vector<UsbDeviceInfo>, UsbError> enumerate(
      std::uint16_t vendor, std::optional<std::uint16_t> product) override;
  /// @copydoc UsbTransport::open
  [[nodiscard]] Result<UsbDeviceHandle, UsbError> open(const UsbDeviceInfo& device) override;
  /// @copydoc UsbTransport::claim_interface
  [[nodiscard]] Result<void, UsbError> claim_interface(const UsbDeviceHandle& handle,
                                                       std::uint8_t interface_number) override;
  /// @copydoc UsbTransport::release_interface
  [[nodiscard]] Result<void, UsbError> release_interface(const UsbDeviceHandle& handle,
                                                         std::uint8_t interface_number) override;
  /// @copydoc UsbTransport::set_alt_setting
  [[nodiscard]] Result<void, UsbError> set_alt_setting(const UsbDeviceHandle& handle,
                                                       std::uint8_t interface_number,
                                                       std::uint8_t alt_setting) override;
  /// @copydoc UsbTransport::kernel_driver_active
  [[nodiscard]] Result<bool, UsbError> kernel_driver_active(const UsbDeviceHandle& handle,
                                                            std::uint8_t interface_number) override;
  /// @copydoc UsbTransport::detach_kernel_driver
  [[nodiscard]] Result<void, UsbError> detach_kernel_driver(const UsbDeviceHandle& handle,
                                                            std::uint8_t interface_number) override;
  /// @copydoc UsbTransport::attach_kernel_driver
  [[nodiscard]] Result<void, UsbError> attach_kernel_driver(const UsbDeviceHandle& handle,
                                                            std::uint8_t interface_number) override;
  /// @copydoc UsbTransport::reset_device
  [[nodiscard]] Result<void, UsbError> reset_device(const UsbDeviceHandle& handle) override;
  /// @copydoc UsbTransport::clear_halt
  [[nodiscard]] Result<void, UsbError> clear_halt(const UsbDeviceHandle& handle,
                                                  std::uint8_t endpoint) override;
  /// @copydoc UsbTransport::control
  [[nodiscard]] Result<std::size_t, UsbError> control(const UsbDeviceHandle& handle,
                                                      const UsbControlSetup& setup,
                                                      std::span<std::byte> data,
                                                      UsbTimeout timeout) override;
  /// @copydoc UsbTransport::bulk
  [[nodiscard]] Result<std::size_t, UsbError> bulk(const UsbDeviceHandle& handle,
                                                   std::uint8_t endpoint, std::span<std::byte> data,
                                                   UsbTimeout timeout) override;
  /// @copydoc UsbTransport::interrupt
  [[nodiscard]] Result<std::size_t, UsbError> interrupt(const UsbDeviceHandle& handle,
                                                        std::uint8_t endpoint,
                                                        std::span<std::byte> data,
                                                        UsbTimeout timeout) override;
  /// @copydoc UsbTransport::max_iso_packet_size
  [[nodiscard]] Result<std::size_t, UsbError> max_iso_packet_size(const UsbDeviceHandle& handle,
                                                                  std::uint8_t endpoint) override;
  /// @copydoc UsbTransport::start_iso
  [[nodiscard]] Result<void, UsbError> start_iso(const UsbDeviceHandle& handle,
                                                 std::uint8_t endpoint, const UsbIsoConfig& config,
                                                 UsbIsoCallback on_packet) override;
  /// @copydoc UsbTransport::stop_iso
  [[nodiscard]] Result<void, UsbError> stop_iso(const UsbDeviceHandle& handle,
                                                std::uint8_t endpoint) override;
  /// @copydoc UsbTransport::iso_stats
  [[nodiscard]] Result<UsbIsoStats, UsbError> iso_stats(const UsbDeviceHandle& handle,
                                                        std::uint8_t endpoint) const override;
  /// @copydoc UsbTransport::handle_events
  [[nodiscard]] Result<void, UsbError> handle_events(UsbTimeout timeout) override;
  /// @copydoc UsbTransport::clock
  [[nodiscard]] const MonotonicClock& clock() const noexcept override { return *clock_; }

 private:
  using OpenDevicePtr = std::unique_ptr<LibusbOpenDevice, LibusbOpenDeviceDeleter>;
  using IsoStreamPtr = std::unique_ptr<LibusbIsoStream, LibusbIsoStreamDeleter>;

  LibusbTransport(libusb_context* context, const MonotonicClock* clock) noexcept;
  void close_device(std::uint32_t id) noexcept override;
  // Defined in libusb_transport.cpp.
  [[nodiscard]] LibusbOpenDevice* find_device(const UsbDeviceHandle& handle) const noexcept;
  [[nodiscard]] libusb_device_handle* native_handle(const UsbDeviceHandle& handle) const noexcept;
  [[nodiscard]] Result<std::size_t, UsbError> sync_transfer(const UsbDeviceHandle& handle,
                                                            std::uint8_t endpoint,
                                                            std::span<std::byte> data,
                                                            UsbTimeout timeout, bool is_bulk);
  [[nodiscard]] Result<void, UsbError> pump(UsbTimeout timeout, int* completed) noexcept;
  void check_not_in_callback() const noexcept;
  // Defined in libusb_discovery.cpp.
  [[nodiscard]] Result<libusb_device_handle*, UsbError> open_native(const UsbDeviceInfo& wanted);
  // Defined in libusb_iso.cpp, beside the stream type.
  [[nodiscard]] LibusbIsoStream* find_stream(std::uint32_t device_id,
                                             std::uint8_t endpoint) const noexcept;
  [[nodiscard]] Result<void, UsbError> stop_stream(LibusbIsoStream& stream);
  void stop_streams_of(std::uint32_t device_id) noexcept;
  void drain(LibusbIsoStream& stream) noexcept;
  void collect_abandoned_streams() noexcept;
  [[nodiscard]] bool release_all_streams() noexcept;

  libusb_context* context_ = nullptr;
  SteadyClock steady_clock_;
  const MonotonicClock* clock_ = nullptr;
  std::vector<OpenDevicePtr> devices_;
  std::vector<IsoStreamPtr> streams_;
  std::vector<IsoStreamPtr> abandoned_streams_;  ///< cancelled but not yet back
  std::uint32_t next_id_ = 1;
  bool in_callback_ =
      false;  ///< true while an iso callback runs: re-entry is a bug (see usb_transport.hpp)
};

}  // namespace orthoflow::drivers
