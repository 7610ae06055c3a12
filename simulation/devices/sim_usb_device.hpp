#pragma once
/// @file
/// @brief SimUsbDevice: what one simulated USB device adds to the simulated host
/// (sim_usb_host.hpp): its descriptors, its own transfers (control, bulk, interrupt, iso packets),
/// its scheduled events and its per-device stepping. The host keeps everything else once for every
/// device: enumeration, addresses, handles and epochs, claims, alternate settings, kernel-driver
/// binding, plug / unplug / replug, iso stream buffering and timing, transfer latencies and the
/// simulated clock.
///
/// A device has one or more USB functions (the Kinect: camera, motor, audio behind its internal
/// hub; the JACO: one), numbered 0..function_count() - 1. Every call names the function. Interfaces
/// 0..SIM_USB_MAX_INTERFACES - 1 may exist; every endpoint belongs to one of them.
/// Implementations: SimKinectUsbDevice (sim_kinect_usb_device.hpp), SimJacoUsbDevice
/// (sim_jaco_usb_device.hpp).
/// Threading: the host's thread only. Determinism: a device's answers are a function of its
/// config, the calls and their simulated times.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>

#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::simulation {

/// @brief A high-speed microframe: iso packets come one per microframe.
inline constexpr std::int64_t USB_MICROFRAME_NS = 125'000;
/// @brief Interfaces a simulated function may have (numbers 0..3).
inline constexpr std::size_t SIM_USB_MAX_INTERFACES = 4;
/// @brief "No such time": an event that never comes.
inline constexpr std::int64_t SIM_USB_NEVER = std::numeric_limits<std::int64_t>::max();

/// @brief How a device answered a control, bulk or interrupt request.
enum class SimControlOutcome : std::uint8_t { OK, PIPE, TIMEOUT };
/// @brief A device's answer: its outcome and the bytes moved (IN: written to the buffer).
struct SimControlReply {
  SimControlOutcome outcome = SimControlOutcome::OK;
  std::size_t bytes = 0;  ///< bytes moved (IN: written to the buffer)
};

/// @brief Transfer type of an endpoint.
enum class SimEndpointType : std::uint8_t { CONTROL, BULK, INTERRUPT, ISO };

/// @brief One endpoint descriptor, as far as the host needs it. Plain data.
struct SimEndpoint {
  SimEndpointType type = SimEndpointType::BULK;
  std::size_t max_packet = 0;    ///< bytes per (micro)frame: ISO max_iso_packet_size(), INTERRUPT
                                 ///< packet size (at most SIM_USB_MAX_INTERRUPT_PACKET)
  std::uint8_t interface = 0;    ///< transfers on it need this interface claimed (not CONTROL)
  std::uint8_t alt_setting = 0;  ///< ISO: it streams only in this alternate setting
  bool simulated = true;  ///< false: listed (max_iso_packet_size answers) but never carries data:
                          ///< transfers, start_iso and clear_halt answer NOT_FOUND
  bool whole_packets = false;  ///< INTERRUPT OUT: exactly max_packet bytes, else INVALID_PARAM
};

/// @brief Largest interrupt packet the host buffers (full and high speed allow at most 1024).
inline constexpr std::size_t SIM_USB_MAX_INTERRUPT_PACKET = 1024;

/// @brief A device's next scheduled event (a fault time).
struct SimDeviceEvent {
  std::int64_t at_ns = SIM_USB_NEVER;  ///< when; SIM_USB_NEVER: none
  bool wakes = true;  ///< true: ends a handle_events() wait; false: happens when time passes it
};

/// @brief What a device's event asks the host to do to it.
enum class SimPlugAction : std::uint8_t {
  NONE,           ///< nothing (the event only changed the device)
  UNPLUG,         ///< pull its cable (SimUsbHost::unplug_device)
  REPLUG,         ///< plug it back (SimUsbHost::replug_device)
  CANCEL_STREAMS  ///< its in-flight iso transfers come back CANCELLED, unrequested
};

/// @brief The device side of the simulated host. Only descriptors and pure queries are pure
/// virtual; every transfer defaults to "not this device's" (PIPE, nothing pending, no packet).
/// @note Not copyable; the host owns it. One thread.
class SimUsbDevice {
 public:
  SimUsbDevice() = default;
  SimUsbDevice(const SimUsbDevice&) = delete;
  SimUsbDevice& operator=(const SimUsbDevice&) = delete;
  virtual ~SimUsbDevice() = default;

  // ---- descriptors ------------------------------------------------------------------------------
  /// @brief The bus it hangs on. @pre none.
  [[nodiscard]] virtual std::uint8_t bus() const noexcept = 0;
  /// @brief Its USB functions; each takes an address at plug-in, absent ones too. @pre none.
  [[nodiscard]] virtual std::size_t function_count() const noexcept = 0;
  /// @brief Addresses taken before its functions' at plug-in (an internal hub: 1). @pre none.
  [[nodiscard]] virtual std::size_t hub_addresses() const noexcept { return 0; }
  /// @brief True if @p function is on the bus now (a re-enumerating function is away for a while;
  /// a function the model lacks never is). @pre function < function_count().
  [[nodiscard]] virtual bool present(std::size_t function, std::int64_t now_ns) const noexcept = 0;
  /// @brief The enumeration record of @p function at its address. @pre present(function, now).
  [[nodiscard]] virtual drivers::UsbDeviceInfo info(std::size_t function) const noexcept = 0;
  /// @brief The host gives @p function the address @p address (at plug-in, and when it comes back
  /// from a re-enumeration). @pre function < function_count().
  virtual void set_address(std::size_t function, std::uint8_t address) noexcept = 0;
  /// @brief Bumped when @p function re-enumerates on its own: handles of an older generation are
  /// dead, its claims are gone and it gets a new address. @pre function < function_count().
  [[nodiscard]] virtual std::uint32_t generation(std::size_t function) const noexcept {
    (void)function;
    return 0;
  }
  /// @brief Alternate settings of @p interface (0: no such interface). @pre function valid.
  [[nodiscard]] virtual std::uint8_t alt_settings(std::size_t function,
                                                  std::uint8_t interface) const noexcept = 0;
  /// @brief True if the OS binds a kernel driver to @p interface at plug-in (gspca_kinect).
  /// @pre function < function_count().
  [[nodiscard]] virtual bool kernel_driver(std::size_t function,
                                           std::uint8_t interface) const noexcept {
    (void)function;
    (void)interface;
    return false;
  }
  /// @brief Endpoint @p address of @p function (0x00: the control endpoint), or nullopt.
  /// @pre function < function_count().
  [[nodiscard]] virtual std::optional<SimEndpoint> endpoint(
      std::size_t function, std::uint8_t address) const noexcept = 0;

  // ---- transfers (the host has checked handle, claim and endpoint; it owns the timing) ---------
  /// @brief A control request at @p now_ns; @p data is the OUT payload or the IN buffer.
  /// @pre The function lists a CONTROL endpoint 0; data.size() <= 65535.
  virtual SimControlReply control(std::size_t function, const drivers::UsbControlSetup& setup,
                                  std::span<std::byte> data, std::int64_t now_ns) noexcept;
  /// @brief A bulk transfer on @p endpoint at @p now_ns. TIMEOUT: nothing to send, or a stall.
  /// @pre @p endpoint is a simulated BULK endpoint of @p function, its interface claimed.
  virtual SimControlReply bulk(std::size_t function, std::uint8_t endpoint,
                               std::span<std::byte> data, std::int64_t now_ns) noexcept;
  /// @brief An interrupt OUT packet arrives at @p now_ns (the end of the transfer's latency).
  /// @pre @p endpoint is a simulated INTERRUPT OUT endpoint of @p function, its interface claimed.
  virtual void interrupt_out(std::size_t function, std::uint8_t endpoint,
                             std::span<const std::byte> packet, std::int64_t now_ns) noexcept;
  /// @brief True if an interrupt IN packet waits on @p endpoint. @pre function valid.
  [[nodiscard]] virtual bool interrupt_pending(std::size_t function,
                                               std::uint8_t endpoint) const noexcept;
  /// @brief Takes the waiting IN packet into @p packet (at least max_packet bytes); returns its
  /// length.
  /// @pre interrupt_pending(function, endpoint).
  virtual std::size_t interrupt_in(std::size_t function, std::uint8_t endpoint,
                                   std::span<std::byte> packet) noexcept;
  /// @brief The packet of microframe @p microframe on iso @p endpoint into @p out; returns its
  /// length (0: idle; more than the host's packet size is an OVERFLOW). Called once per microframe
  /// in increasing order, once the microframe has elapsed. @pre out.size() >= max_packet.
  virtual std::size_t iso_packet(std::size_t function, std::uint8_t endpoint,
                                 std::int64_t microframe, std::span<std::byte> out) noexcept;

  // ---- life cycle and time ----------------------------------------------------------------------
  /// @brief A port reset of @p function (same descriptors, the handle stays valid).
  /// @pre No stream of it runs.
  virtual void reset(std::size_t function, std::int64_t now_ns) noexcept;
  /// @brief The cable was pulled at @p now_ns (the host already failed its streams). @pre none.
  virtual void unplugged(std::int64_t now_ns) noexcept { (void)now_ns; }
  /// @brief The cable is back at @p now_ns (before the host assigns new addresses). @pre none.
  virtual void replugged(std::int64_t now_ns) noexcept { (void)now_ns; }
  /// @brief Simulated time reached @p now_ns (called whenever the host's clock moves).
  /// @pre now_ns never decreases.
  virtual void advance(std::int64_t now_ns) noexcept { (void)now_ns; }
  /// @brief Its next scheduled event while it is @p plugged (or not). @pre none.
  [[nodiscard]] virtual SimDeviceEvent next_event(bool plugged) const noexcept {
    (void)plugged;
    return {};
  }
  /// @brief The host runs the event next_event(plugged) named, at its time @p at_ns: the device
  /// marks it done and says what the host must do. @pre at_ns == next_event(plugged).at_ns.
  virtual SimPlugAction take_event(std::int64_t at_ns, bool plugged) noexcept {
    (void)at_ns;
    (void)plugged;
    return SimPlugAction::NONE;
  }
};

// The defaults: a device without such transfers (the host only calls them on endpoints the device
// lists, so reaching one is a device that lists more than it handles).
inline SimControlReply SimUsbDevice::control(std::size_t, const drivers::UsbControlSetup&,
                                             std::span<std::byte>, std::int64_t) noexcept {
  return {SimControlOutcome::PIPE, 0};
}
inline SimControlReply SimUsbDevice::bulk(std::size_t, std::uint8_t, std::span<std::byte>,
                                          std::int64_t) noexcept {
  return {SimControlOutcome::PIPE, 0};
}
inline void SimUsbDevice::interrupt_out(std::size_t, std::uint8_t, std::span<const std::byte>,
                                        std::int64_t) noexcept {}
inline bool SimUsbDevice::interrupt_pending(std::size_t, std::uint8_t) const noexcept {
  return false;
}
inline std::size_t SimUsbDevice::interrupt_in(std::size_t, std::uint8_t,
                                              std::span<std::byte>) noexcept {
  return 0;
}
inline std::size_t SimUsbDevice::iso_packet(std::size_t, std::uint8_t, std::int64_t,
                                            std::span<std::byte>) noexcept {
  return 0;
}
inline void SimUsbDevice::reset(std::size_t, std::int64_t) noexcept {}

}  // namespace orthoflow::simulation
