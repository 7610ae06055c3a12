#pragma once
/// @file
/// @brief ForwardingTransport: the one generic decorator of the UsbTransport seam
/// (drivers/usb/usb_transport.hpp): forwards every call to an inner transport, mapping its own
/// handle ids to the inner transport's handles, and shows every call to one virtual hook,
/// on_call(), before and after forwarding. A recorder, a replayer or a test derives from it and
/// overrides only the hook (USB_TESTING.md 3.4).
///
/// Handles: open() opens the inner device and hands out an id of its own (from 1, never reused);
/// closing it closes the inner handle. A handle this decorator did not open (or already closed)
/// is forwarded as an empty handle, so the inner transport answers NOT_OPEN by its own rules.
/// Iso callbacks go to the inner transport unchanged (they run inside its handle_events()).
/// clock() is the inner transport's.
/// Threading: that of the inner transport (one thread). Determinism: adds none of its own.
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::simulation {

/// @brief The seam's operations, one per UsbTransport call (CLOSE: a handle closed).
enum class SeamOp : std::uint8_t {
  ENUMERATE,
  OPEN,
  CLOSE,
  CLAIM_INTERFACE,
  RELEASE_INTERFACE,
  SET_ALT_SETTING,
  KERNEL_DRIVER_ACTIVE,
  DETACH_KERNEL_DRIVER,
  ATTACH_KERNEL_DRIVER,
  RESET_DEVICE,
  CLEAR_HALT,
  CONTROL,
  BULK,
  INTERRUPT,
  MAX_ISO_PACKET_SIZE,
  START_ISO,
  STOP_ISO,
  ISO_STATS,
  HANDLE_EVENTS
};

/// @brief Lower-case name, e.g. "interrupt". @pre none. @note Never allocates; thread-safe.
[[nodiscard]] const char* to_string(SeamOp op) noexcept;

/// @brief One seam call as the hook sees it: the arguments (those the operation has), and once
/// forwarded (done), its outcome. Views the caller's data: valid only during on_call().
struct SeamCall {
  SeamOp op = SeamOp::ENUMERATE;
  bool done = false;         ///< false: about to be forwarded; true: forwarded, outcome below
  std::uint32_t handle = 0;  ///< this decorator's handle id (0: the call takes none)
  std::uint8_t number = 0;   ///< the interface (claims, alt settings, kernel drivers) or endpoint
  std::uint8_t alt_setting = 0;
  std::uint16_t vendor = 0;                        ///< ENUMERATE
  std::optional<std::uint16_t> product{};          ///< ENUMERATE
  const drivers::UsbDeviceInfo* device = nullptr;  ///< OPEN
  drivers::UsbControlSetup setup{};                ///< CONTROL
  std::span<std::byte> data{};  ///< CONTROL / BULK / INTERRUPT: OUT payload, or IN bytes once done
  const drivers::UsbIsoConfig* iso = nullptr;  ///< START_ISO
  drivers::UsbTimeout timeout{0};              ///< transfers and HANDLE_EVENTS
  std::optional<drivers::UsbError> error{};    ///< done: the inner call's error, if it failed
  std::size_t bytes = 0;                       ///< done: bytes moved (transfers), or the count
};

/// @brief Forwards the seam to @p inner. @note Not thread-safe (the inner transport's thread).
class ForwardingTransport : public drivers::UsbTransport {
 public:
  /// @brief A decorator of @p inner. @pre @p inner outlives it and every handle it opened.
  explicit ForwardingTransport(drivers::UsbTransport& inner) : inner_(inner) {}
  ~ForwardingTransport() override = default;

  /// @brief The transport forwarded to. @pre none.
  [[nodiscard]] drivers::UsbTransport& inner() noexcept { return inner_; }

  [[nodiscard]] Result<std::vector<drivers::UsbDeviceInfo>, drivers::UsbError> enumerate(
      std::uint16_t vendor, std::optional<std::uint16_t> product) override;
  [[nodiscard]] Result<drivers::UsbDeviceHandle, drivers::UsbError> open(
      const drivers::UsbDeviceInfo& device) override;
  [[nodiscard]] Result<void, drivers::UsbError> claim_interface(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> release_interface(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> set_alt_setting(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number,
      std::uint8_t alt_setting) override;
  [[nodiscard]] Result<bool, drivers::UsbError> kernel_driver_active(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> detach_kernel_driver(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> attach_kernel_driver(
      const drivers::UsbDeviceHandle& handle, std::uint8_t interface_number) override;
  [[nodiscard]] Result<void, drivers::UsbError> reset_device(
      const drivers::UsbDeviceHandle& handle) override;
  [[nodiscard]] Result<void, drivers::UsbError> clear_halt(const drivers::UsbDeviceHandle& handle,
                                                           std::uint8_t endpoint) override;
  [[nodiscard]] Result<std::size_t, drivers::UsbError> control(
      const drivers::UsbDeviceHandle& handle, const drivers::UsbControlSetup& setup,
      std::span<std::byte> data, drivers::UsbTimeout timeout) override;
  [[nodiscard]] Result<std::size_t, drivers::UsbError> bulk(const drivers::UsbDeviceHandle& handle,
                                                            std::uint8_t endpoint,
                                                            std::span<std::byte> data,
                                                            drivers::UsbTimeout timeout) override;
  [[nodiscard]] Result<std::size_t, drivers::UsbError> interrupt(
      const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint, std::span<std::byte> data,
      drivers::UsbTimeout timeout) override;
  [[nodiscard]] Result<std::size_t, drivers::UsbError> max_iso_packet_size(
      const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint) override;
  [[nodiscard]] Result<void, drivers::UsbError> start_iso(
      const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint,
      const drivers::UsbIsoConfig& config, drivers::UsbIsoCallback on_packet) override;
  [[nodiscard]] Result<void, drivers::UsbError> stop_iso(const drivers::UsbDeviceHandle& handle,
                                                         std::uint8_t endpoint) override;
  [[nodiscard]] Result<drivers::UsbIsoStats, drivers::UsbError> iso_stats(
      const drivers::UsbDeviceHandle& handle, std::uint8_t endpoint) const override;
  [[nodiscard]] Result<void, drivers::UsbError> handle_events(drivers::UsbTimeout timeout) override;
  [[nodiscard]] const drivers::MonotonicClock& clock() const noexcept override {
    return inner_.clock();
  }

 protected:
  /// @brief The hook: sees every call twice, before forwarding (done false) and after (done
  /// true, with its outcome). The default does nothing. @pre Must not call this transport.
  /// @note const calls (iso_stats) are shown too, hence const.
  virtual void on_call(const SeamCall& call) const { (void)call; }
  void close_device(std::uint32_t id) noexcept override;

 private:
  [[nodiscard]] const drivers::UsbDeviceHandle& inner_handle(
      const drivers::UsbDeviceHandle& handle) const noexcept;
  [[nodiscard]] SeamCall call_on(SeamOp op, const drivers::UsbDeviceHandle& handle,
                                 std::uint8_t number = 0) const noexcept;
  template <class T>
  Result<T, drivers::UsbError> finish(SeamCall& call, Result<T, drivers::UsbError> result) const;

  drivers::UsbTransport& inner_;
  std::map<std::uint32_t, drivers::UsbDeviceHandle> handles_;  // own id -> the inner handle
  std::uint32_t next_id_ = 1;
  drivers::UsbDeviceHandle empty_{};
};

template <class T>
Result<T, drivers::UsbError> ForwardingTransport::finish(
    SeamCall& call, Result<T, drivers::UsbError> result) const {
  call.done = true;
  if (!result) call.error = result.error();
  on_call(call);
  return result;
}

}  // namespace orthoflow::simulation
