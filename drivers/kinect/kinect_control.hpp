#pragma once
/// @file
/// @brief KinectControl: the camera's GM/RB command exchange over the USB seam
/// (specs/KINECT_V1.md 4), with the tag discipline, the reply polling rule (0 and 512 bytes mean
/// "not ready", the xHCI quirk), bounded polls and retries, register writes and scripts, and the
/// calibration reads of section 5.3.
///
/// Unlike libfreenect (no timeout, unbounded polling), every exchange is bounded: at most
/// ControlPolicy::max_polls reply reads of transfer_timeout each, at most `retries` resends, and
/// never longer than command_deadline in all; the error names the opcode and the last reply check.
#include <chrono>
#include <cstdint>
#include <span>
#include <string>

#include "core/result.hpp"
#include "drivers/kinect/kinect_protocol.hpp"
#include "drivers/usb/usb_transport.hpp"

namespace orthoflow::drivers::kinect {

/// @brief How patient the control exchange is.
struct ControlPolicy {
  UsbTimeout transfer_timeout{500};  ///< per control transfer (the kernel driver's 500 ms)
  std::uint32_t max_polls = 100;     ///< reply reads per attempt before giving up (NOT_READY)
  std::uint32_t retries = 2;         ///< resends after a bad reply, a timeout or a poll limit
  /// Whatever the polls and retries, one command gives up after this long (transport clock): a
  /// stalled device costs the USB thread at most this, plus one transfer timeout.
  std::chrono::milliseconds command_deadline{2000};
};

/// @brief Counters of the control exchange (STYLE rule 16: every retry is data).
struct ControlStats {
  std::uint64_t commands = 0;         ///< commands that succeeded
  std::uint64_t failures = 0;         ///< commands that failed after every retry
  std::uint64_t retries = 0;          ///< resends
  std::uint64_t not_ready_polls = 0;  ///< reply reads that returned 0 or 512 bytes
  std::uint64_t bad_replies = 0;      ///< replies refused by check_reply (magic, opcode, tag, len)
  std::uint64_t timeouts = 0;         ///< control transfers that timed out
  std::uint64_t device_statuses = 0;  ///< replies whose status word was not 0
};

/// @brief Why a Kinect operation failed. Trivially copyable; never allocates.
struct KinectError {
  enum class Code : std::uint8_t {
    USB,               ///< the transport failed: see usb
    BAD_REPLY,         ///< every attempt got a malformed reply: see reply
    NOT_READY,         ///< the device never answered within the poll limit
    DEVICE_STATUS,     ///< the device answered with a nonzero status word: see status
    BAD_CALIBRATION,   ///< a calibration reply did not parse: see parse
    REPLY_TOO_LONG,    ///< the reply payload does not fit the caller's buffer
    NO_CAMERA,         ///< no Kinect v1 camera found (or not the serial asked for)
    INVALID_ARGUMENT,  ///< the request cannot be framed (odd or oversize payload)
    STALLED,           ///< the stream watchdog saw no complete frame in time
  };
  Code code = Code::USB;
  UsbError usb{};
  ReplyCheck reply = ReplyCheck::OK;
  ParseCheck parse = ParseCheck::OK;
  std::uint16_t opcode = 0;
  std::uint16_t status = 0;
};
/// @brief Lower-case name of @p code. @pre none.
[[nodiscard]] const char* to_string(KinectError::Code code) noexcept;
/// @brief One line naming what failed, e.g. "bad_reply: opcode 0x03, wrong_tag". @note Allocates.
[[nodiscard]] std::string to_string(const KinectError& error);

/// @brief The command channel of one open camera.
/// @note Belongs to the transport's thread. Never allocates.
class KinectControl {
 public:
  /// @brief Commands go to @p camera through @p transport. @pre Both outlive this object.
  KinectControl(UsbTransport& transport, const UsbDeviceHandle& camera,
                ControlPolicy policy = {}) noexcept
      : transport_(&transport), camera_(&camera), policy_(policy) {}

  /// @brief Sends @p opcode with @p payload and copies the reply payload (status word first) into
  /// @p reply. @return the reply payload's size. The tag advances only on success.
  [[nodiscard]] Result<std::size_t, KinectError> command(std::uint16_t opcode,
                                                         std::span<const std::byte> payload,
                                                         std::span<std::byte> reply);
  /// @brief SET_PARAM: @p reg = @p value; the reply must be the 2-byte status 0.
  [[nodiscard]] Result<void, KinectError> write_register(std::uint16_t reg, std::uint16_t value);
  /// @brief GET_PARAM: the value of @p reg.
  [[nodiscard]] Result<std::uint16_t, KinectError> read_register(std::uint16_t reg);
  /// @brief Every write of @p script in order, honouring its pauses (on the transport's clock,
  /// pumping events while waiting). Stops at the first failure.
  [[nodiscard]] Result<void, KinectError> run(RegisterScript script);
  /// @brief The four calibration reads of KINECT_V1.md 5.3 for a @p model camera.
  [[nodiscard]] Result<Calibration, KinectError> read_calibration(Model model);

  /// @brief The tag the next command carries. @pre none.
  [[nodiscard]] std::uint16_t tag() const noexcept { return tag_; }
  /// @brief The counters so far. @pre none.
  [[nodiscard]] const ControlStats& stats() const noexcept { return stats_; }

 private:
  [[nodiscard]] Result<std::size_t, KinectError> attempt(std::uint16_t opcode,
                                                         std::span<const std::byte> frame,
                                                         std::span<std::byte> reply,
                                                         std::int64_t deadline_ns);
  [[nodiscard]] Result<std::size_t, KinectError> algorithm_param(std::uint16_t param_id,
                                                                 std::uint16_t resolution,
                                                                 std::span<std::byte> reply);

  UsbTransport* transport_;
  const UsbDeviceHandle* camera_;
  ControlPolicy policy_;
  std::uint16_t tag_ = 0;
  ControlStats stats_{};
};

}  // namespace orthoflow::drivers::kinect
