#pragma once
/// @file
/// @brief The arm's stop, reachable from any process (docs/SAFETY.md, "a stop everyone can
/// reach"): ArmStopRequest on the iceoryx topic `orthoflow/jaco/stop` (what `orthoflow arm stop`,
/// the web view's stop button and the DDS bridge's stop topic send) and ArmStopAck on
/// `orthoflow/jaco/stop_ack` (what the process holding the arm answers once the arm is halted and
/// latched). Same header rules as every payload: type id, version, payload_bytes at offset 48.
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace orthoflow::engine {

inline constexpr std::uint32_t ARM_STOP_TYPE_ID = 0x5053464FU;      ///< "OFSP"
inline constexpr std::uint32_t ARM_STOP_ACK_TYPE_ID = 0x4B53464FU;  ///< "OFSK"
inline constexpr std::uint16_t ARM_STOP_VERSION = 1;
inline constexpr const char* ARM_STOP_TOPIC = "orthoflow/jaco/stop";
inline constexpr const char* ARM_STOP_ACK_TOPIC = "orthoflow/jaco/stop_ack";

/// @brief "Stop the arm", with who asks and why.
struct alignas(64) ArmStopRequest {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint64_t request_id;  ///< chosen by the requester; echoed in the ack
  std::int64_t request_ns;   ///< requester's steady clock (CLOCK_MONOTONIC) when it asked
  std::int32_t requester_pid;
  std::int32_t target_pid;  ///< the holder's pid (its state directory names it); 0: any holder
  std::uint64_t reserved2[2];
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(ArmStopRequest)
  char reason[64];              ///< NUL-terminated, e.g. "web view", "orthoflow arm stop"

  void reset() noexcept {
    *this = ArmStopRequest{};
    type_id = ARM_STOP_TYPE_ID;
    version = ARM_STOP_VERSION;
    payload_bytes = sizeof(ArmStopRequest);
  }
};
static_assert(offsetof(ArmStopRequest, payload_bytes) == 48);
static_assert(std::is_trivially_copyable_v<ArmStopRequest>);

/// @brief The holder's answer: the arm is halted (zero velocity commanded, FIFO erased, joystick
/// released) and the stop latched.
struct alignas(64) ArmStopAck {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint64_t request_id;  ///< the request's
  std::int64_t request_ns;   ///< the request's
  std::int64_t halted_ns;    ///< holder's steady clock when zero velocity was commanded
  std::int32_t requester_pid;
  std::int32_t holder_pid;
  std::uint32_t was_moving;  ///< 1: the arm was moving when the request arrived
  std::uint32_t reserved1;
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(ArmStopAck)
  char holder[64];              ///< what holds the arm, e.g. "orthoflow task run"

  void reset() noexcept {
    *this = ArmStopAck{};
    type_id = ARM_STOP_ACK_TYPE_ID;
    version = ARM_STOP_VERSION;
    payload_bytes = sizeof(ArmStopAck);
  }
};
static_assert(offsetof(ArmStopAck, payload_bytes) == 48);
static_assert(std::is_trivially_copyable_v<ArmStopAck>);

}  // namespace orthoflow::engine
