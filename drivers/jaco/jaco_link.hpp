#pragma once
/// @file
/// @brief JacoLink: the JACO's request/reply exchange over the USB seam (specs/JACO.md 4 and 10):
/// one OUT packet, one IN packet, the reply's command id checked, every transfer bounded; the
/// flush on open; and the start-up reads (client info, firmware, arm state). Belongs to one thread
/// (the driver's USB thread), like its transport.
///
/// Retry rule: a read request ("get") is sent again after a bad or missing reply (at most
/// LinkPolicy::retries times); a motion or mode command never is, because a lost reply does not
/// say whether the arm took the command: the caller stops the arm instead.
#include <chrono>
#include <cstdint>
#include <string>

#include "core/result.hpp"
#include "drivers/jaco/jaco_protocol.hpp"
#include "drivers/jaco/jaco_safety.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::jaco {

/// @brief Why a JACO operation failed. Trivially copyable; never allocates.
struct JacoError {
  enum class Code : std::uint8_t {
    USB,            ///< the transport failed: see usb (NO_DEVICE on unplug, TIMEOUT on a stall)
    BAD_REPLY,      ///< the arm answered with a packet check failure: see check
    NO_ARM,         ///< no JACO found (or not the serial asked for)
    NOT_HOMED,      ///< the arm did not leave NOINIT / reach its goal within the deadline
    REFUSED,        ///< the safety layer refused the command: see violation
    ESTOP,          ///< the emergency stop is latched: reset it first
    FAULT,          ///< the link failed earlier (unplug, stall): re-initialise the arm
    BUSY,           ///< the command queue is full
    INVALID_STATE,  ///< the command is not possible now (e.g. RETRACT from NORMAL)
  };
  Code code = Code::USB;
  UsbError usb{};
  PacketCheck check = PacketCheck::OK;
  Command command = Command::GET_ANG_POS;  ///< the command that failed, where one did
  SafetyViolation violation{};
};
[[nodiscard]] const char* to_string(JacoError::Code code) noexcept;
/// @brief A sentence for logs and the CLI, e.g. "usb: no_device in interrupt (native 0) during
/// get_ang_pos". @note Allocates.
[[nodiscard]] std::string to_string(const JacoError& error);

/// @brief How patient the link is. Every transfer has a deadline: a full-speed interrupt exchange
/// takes about 2 ms (JACO.md 9), so a transfer that has not completed in transfer_timeout is lost,
/// and a silent arm costs the control thread at most (retries + 1) x 2 x transfer_timeout before
/// the cycle goes on (the guard declares the FAULT meanwhile: jaco_controller.hpp).
struct LinkPolicy {
  UsbTimeout transfer_timeout{6};  ///< per interrupt transfer (libkindrv waits 1 s)
  std::uint32_t retries = 1;       ///< resends of a read request
  UsbTimeout flush_timeout{20};    ///< per read while flushing stale replies at open
  std::uint32_t flush_reads = 32;  ///< at most this many stale replies discarded
};

/// @brief Counters of the exchange (STYLE rule 16: every retry is data).
struct LinkStats {
  std::uint64_t exchanges = 0;    ///< successful request/reply pairs
  std::uint64_t retries = 0;      ///< resends of read requests
  std::uint64_t bad_replies = 0;  ///< replies refused by check_reply or a parser
  std::uint64_t timeouts = 0;     ///< transfers that timed out
  std::uint64_t flushed = 0;      ///< stale replies discarded at open
};

/// @brief What the start-up reads found.
struct ArmIdentity {
  ClientInfo client{};
  Firmware firmware{};
  Model model = Model::JACO_V1;
  UsbDeviceInfo device{};
};

class JacoLink {
 public:
  /// @brief Opens @p device on @p transport, claims interface 0 and flushes stale replies.
  /// @pre @p transport outlives the link.
  [[nodiscard]] static Result<JacoLink, JacoError> open(UsbTransport& transport,
                                                        const UsbDeviceInfo& device,
                                                        LinkPolicy policy = {});
  /// @brief Sends @p request and reads its reply into @p reply (command id checked). Reads are
  /// retried per the policy; other commands are not. @pre none.
  [[nodiscard]] Result<void, JacoError> exchange(const Packet& request, Packet& reply) noexcept;
  /// @brief exchange() for an argument-less command (START_API_CONTROL, ERASE, control modes).
  [[nodiscard]] Result<void, JacoError> command(Command command) noexcept;
  /// @brief Reads a nine-float reply (positions, velocities, forces, currents). @pre none.
  [[nodiscard]] Result<NineFloats, JacoError> read_nine(Command command) noexcept;
  /// @brief Client info (55 slices, 1 and 2 decoded), firmware and the model. @pre none.
  [[nodiscard]] Result<ArmIdentity, JacoError> read_identity() noexcept;
  /// @brief The arm state: command 62 on DSP >= 5 (one exchange), else command 200 (19 exchanges).
  [[nodiscard]] Result<ArmState, JacoError> read_state(bool dsp5) noexcept;
  /// @brief The sensor block (voltage, current, accelerometer, temperatures). @pre none.
  [[nodiscard]] Result<SensorInfo, JacoError> read_sensors() noexcept;

  [[nodiscard]] const LinkStats& stats() const noexcept { return stats_; }
  [[nodiscard]] UsbTransport& transport() noexcept { return *transport_; }
  [[nodiscard]] const UsbDeviceInfo& device() const noexcept { return device_; }

 private:
  JacoLink(UsbTransport& transport, UsbDeviceHandle handle, const UsbDeviceInfo& device,
           LinkPolicy policy) noexcept
      : transport_(&transport), handle_(std::move(handle)), device_(device), policy_(policy) {}
  Result<void, JacoError> exchange_once(const Packet& request, Packet& reply) noexcept;
  void flush() noexcept;

  UsbTransport* transport_ = nullptr;
  UsbDeviceHandle handle_{};
  UsbDeviceInfo device_{};
  LinkPolicy policy_{};
  LinkStats stats_{};
};

/// @brief The JACOs on @p transport (vendor 0x22CD, product 0). @note Allocates (start-up only).
[[nodiscard]] Result<std::vector<UsbDeviceInfo>, JacoError> list_arms(UsbTransport& transport);

}  // namespace orthoflow::drivers::jaco
