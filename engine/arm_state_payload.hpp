#pragma once
/// @file
/// @brief ArmStatePayload: one snapshot of the arm as one fixed-size POD, what
/// `orthoflow arm state --follow --publish` sends at the arm's 100 Hz on the iceoryx topic
/// `orthoflow/jaco/state` (docs/JACO.md). With frame_payload.hpp and object_list_payload.hpp this
/// is where orthoflow's message schemas live. Same header rules as every payload: type id, version,
/// payload_bytes at offset 48. Plain numbers only: the schema does not depend on the driver's types
/// (apps/ fills it from drivers::jaco::ArmSnapshot).
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace orthoflow::engine {

inline constexpr std::uint32_t ARM_STATE_TYPE_ID = 0x5341464FU;  ///< "OFAS" in little-endian bytes
/// @brief The topic an arm publishes its states on (`orthoflow arm state --publish`, `orthoflow
/// task run`) and the robot-body filter reads by default.
inline constexpr const char* ARM_STATE_TOPIC = "orthoflow/jaco/state";
inline constexpr std::uint16_t ARM_STATE_VERSION = 2;  ///< 2: held_m

/// @brief Flags of ArmStatePayload::flags.
inline constexpr std::uint32_t ARM_ESTOP = 1U << 0;  ///< the emergency stop is latched
inline constexpr std::uint32_t ARM_FAULT = 1U << 1;  ///< the link failed: re-initialise the arm

struct alignas(64) ArmStatePayload {
  std::uint32_t type_id;
  std::uint16_t version;
  std::uint16_t reserved0;
  std::uint32_t flags;      ///< ARM_* bits
  std::int32_t arm_state;   ///< JACO.md 7.3 retract mode (6 NOINIT, 1 HOME, 3 RETRACT, ...)
  std::uint64_t cycle;      ///< the driver's control cycle (100 Hz)
  std::int64_t stamp_ns;    ///< host steady clock (CLOCK_MONOTONIC, as frame stamps) at the read
  std::uint32_t control;    ///< drivers::jaco::ControlState (0 idle, 1 moving, ...)
  std::uint32_t last_stop;  ///< drivers::jaco::StopReason of the last motion
  std::uint64_t reserved1;
  std::uint64_t payload_bytes;  ///< offset 48: sizeof(ArmStatePayload)
  std::uint64_t watchdog_stops;
  double joints_deg[6];  ///< actuator angles
  double velocity_deg_s[6];
  double fingers[3];     ///< the model's units (v1 0..~60, JACO2 0..~6800)
  double position_m[3];  ///< forward kinematics of joints_deg, base frame
  double theta_rad[3];   ///< R = Rx * Ry * Rz
  float currents_a[6];
  float voltage_v;
  float reserved2;
  /// What the hand holds, written by whoever runs the task (the driver alone does not know): a
  /// capsule whose ends are offsets from position_m in the base frame (ax, ay, az, bx, by, bz) and
  /// its radius (m); radius 0: nothing held. The body filter removes it with the arm, so the held
  /// object is never seen, nor merged with what it passes over, as an object on the table.
  double held_m[7];

  /// @brief Writes type id, version and payload_bytes; zeroes the rest. No allocation.
  void reset() noexcept {
    *this = ArmStatePayload{};
    type_id = ARM_STATE_TYPE_ID;
    version = ARM_STATE_VERSION;
    payload_bytes = sizeof(ArmStatePayload);
  }
};
static_assert(offsetof(ArmStatePayload, payload_bytes) == 48);
static_assert(std::is_trivially_copyable_v<ArmStatePayload>);

}  // namespace orthoflow::engine
