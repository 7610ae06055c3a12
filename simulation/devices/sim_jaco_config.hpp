#pragma once
/// @file
/// @brief The configuration of a simulated Kinova JACO (sim_jaco_arm.hpp): the arm's identity,
/// start state, poses, speeds, constant sensor answers, fault knobs, and the counters the arm
/// keeps. Plain data with defaults; SimJacoArm validates it. [I] marks a documented choice where
/// specs/JACO.md is unsure.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "drivers/jaco/jaco_protocol.hpp"

namespace orthoflow::simulation {

/// @brief Replies the arm holds for the IN endpoint before the oldest is lost [I].
inline constexpr std::size_t SIM_JACO_REPLY_QUEUE = 16;

/// @brief The control mode of JACO.md 10 step 8.
enum class SimJacoControlMode : std::uint8_t { ANGULAR, CARTESIAN };

/// @brief The default noise-free sensor readings (111): 24 V, 0.45 A, 1 g up, 27-31 degrees C.
inline constexpr drivers::jaco::SensorInfo SIM_JACO_SENSORS{
    24.0F,
    0.45F,
    {0.0F, 0.0F, 1.0F},
    {31.0F, 31.0F, 30.0F, 29.0F, 29.0F, 28.0F},
    {27.0F, 27.0F, 27.0F}};
/// @brief The default idle currents in A (110 and 113).
inline constexpr drivers::jaco::NineFloats SIM_JACO_IDLE_CURRENTS{
    {0.3F, 0.5F, 0.4F, 0.1F, 0.1F, 0.1F}, {0.05F, 0.05F, 0.05F}};

/// @brief Fault knobs; all off by default. Rates are per OUT packet in [0, 1].
struct SimJacoFaults {
  double drop_out_rate = 0.0;       ///< the OUT moves on USB but the arm never sees it: no effect,
                                    ///< no reply (the next IN times out)
  double in_timeout_rate = 0.0;     ///< the command acts but its reply is never queued
  double garbage_reply_rate = 0.0;  ///< the reply is 64 seeded random bytes whose command id never
                                    ///< matches the request's
  double corrupt_body_rate = 0.0;   ///< right header, random body with float 0 a NaN
  double wrong_command_rate = 0.0;  ///< a valid reply carrying command id + 1
  std::uint32_t stale_replies = 0;  ///< replies (command 15) already queued at plug-in and after
                                    ///< replug: the driver's flush-on-open must eat them
  bool never_leave_noinit = false;  ///< button 2 does nothing in NOINIT: the arm stays there
  /// DSP >= 5 quirk (JACO.md 9): a 305 arriving more than fw5_quirk_window_ns after the previous
  /// 305 (or as the first) is acked but ignored; one within the window acts. So a single packet
  /// after a pause is lost, while libkindrv's double send 100 ms apart lands.
  bool fw5_ignore_first_joystick = false;
  std::int64_t fw5_quirk_window_ns = 150'000'000;
  std::optional<std::int64_t> unplug_at_ns{};  ///< the host unplugs the cable then (the arm itself
                                               ///< keeps running: SimJacoTransport)
  /// From silent_from_ns until silent_until_ns the arm neither hears nor answers anything (a hung
  /// link): OUTs have no effect, INs time out, what the FIFO holds keeps running.
  std::optional<std::int64_t> silent_from_ns{};
  std::int64_t silent_until_ns = 0;
};

/// @brief How the joints move (the physics the monitor's assumptions are tested against,
/// docs/SAFETY.md). Each joint's velocity follows its command at most at accel_deg_s2 when
/// speeding up and decel_deg_s2 when slowing down; a motion packet (308, 305, 301) acts
/// command_latency_ns after it arrives. Infinite rates and zero latency give the old ideal arm.
struct SimJacoDynamics {
  double accel_deg_s2 = 150.0;
  double decel_deg_s2 = 100.0;
  std::int64_t command_latency_ns = 10'000'000;
  /// @brief The ideal arm: speeds jump, packets act at the next cycle. @pre none.
  [[nodiscard]] static SimJacoDynamics ideal() noexcept { return {1e12, 1e12, 0}; }
};

/// @brief One simulated arm. Plain data with defaults (a JACO2 on DSP 5.2); validated by the
/// constructor. sim_jaco_v1_config() gives a JACO v1 on DSP 4.
struct SimJacoConfig {
  drivers::jaco::Model model =
      drivers::jaco::Model::JACO2;          ///< finger units: v1 0..60, JACO2 0..6800
  std::string model_string = "JACO2 6DOF";  ///< client-info strings: at most 19 chars each
  std::string serial = "PJ00650019161750";
  std::string client_name = "sim-jaco";
  std::string client_id = "SIM-0001";
  std::string organisation = "orthoflow";
  drivers::jaco::FirmwareVersion dsp{5, 2, 0};  ///< DSP >= 5: 62, velocities on 114, axis order
  drivers::jaco::FirmwareVersion actuators{5, 2, 0};  ///< reported for all six actuators
  drivers::jaco::FirmwareVersion fingers_fw{1, 3, 0};
  std::string usb_serial{};  ///< the USB iSerialNumber enumerate() shows; empty [I: unknown]
  std::uint8_t bus = 1;      ///< the host's bus number for it
  std::uint8_t port = 1;     ///< root-hub port
  /// NOINIT (power-up), NORMAL, READY_STANDBY or RETRACT_STANDBY.
  drivers::jaco::ArmState start_state = drivers::jaco::ArmState::NOINIT;
  /// Start pose; nullopt: home_joints in READY_STANDBY, else retract_joints.
  std::optional<drivers::jaco::JointAngles> start_joints{};
  std::array<double, drivers::jaco::FINGERS> start_fingers{};
  /// HOME and RETRACT in actuator degrees, inside jaco_joint_limits(): HOME is Kinova's documented
  /// Home rounded (drivers::jaco::HOME_JOINTS); RETRACT is illustrative, not Kinova's value.
  drivers::jaco::JointAngles home_joints = drivers::jaco::HOME_JOINTS;
  drivers::jaco::JointAngles retract_joints{270.0, 210.0, 30.0, 270.0, 90.0, 90.0};
  /// Top joint speeds in deg/s (JACO2: about 36 on joints 1-3, 48 on 4-6).
  std::array<double, drivers::jaco::JOINTS> max_joint_speed_deg_s{36.0, 36.0, 36.0,
                                                                  48.0, 48.0, 48.0};
  std::optional<double> finger_speed{};  ///< finger units/s; nullopt: finger_max / 2
  std::optional<double> finger_max{};    ///< nullopt: 60 (v1) or 6800 (JACO2)
  double max_linear_speed_m_s = 0.2;     ///< Cartesian joystick / velocity points
  double max_angular_speed_rad_s = 0.6;
  std::optional<std::int64_t> held_home_to_retract_ns = 500'000'000;  ///< nullopt: never
  drivers::jaco::SensorInfo sensors = SIM_JACO_SENSORS;               ///< 111
  drivers::jaco::NineFloats cart_force{};                             ///< 108
  drivers::jaco::NineFloats ang_force{};                              ///< 109
  drivers::jaco::NineFloats ang_current = SIM_JACO_IDLE_CURRENTS;     ///< 110
  drivers::jaco::NineFloats motor_current = SIM_JACO_IDLE_CURRENTS;   ///< 113
  std::uint64_t fault_seed = 1;  ///< seeds the core::Rng of every random fault
  SimJacoFaults faults{};
  SimJacoDynamics dynamics{};
};

/// @brief A JACO v1 on DSP 4.2: model string "JACO v1", fingers 0..60, 20 / 30 deg/s joints.
[[nodiscard]] SimJacoConfig sim_jaco_v1_config();

/// @brief What the arm saw and did (STYLE rule 16: every loss is data).
struct SimJacoCounters {
  std::uint64_t packets = 0;             ///< OUT packets given to the arm (dropped ones included)
  std::uint64_t replies = 0;             ///< replies queued
  std::uint64_t replies_lost = 0;        ///< replies pushed out of a full queue, or cleared
  std::uint64_t unknown_commands = 0;    ///< ids without a reply
  std::uint64_t malformed_commands = 0;  ///< 305 / 308 bodies that failed to decode (acked)
  std::uint64_t ignored_commands = 0;    ///< 305 / 308 without API control or in NOINIT
  std::uint64_t joystick_ignored = 0;    ///< 305 lost to the DSP >= 5 quirk
  std::uint64_t points_queued = 0;
  std::uint64_t points_dropped = 0;   ///< arrived at a full FIFO
  std::uint64_t points_rejected = 0;  ///< outside the limits or without IK solution
  std::uint64_t points_completed = 0;
  std::uint64_t points_erased = 0;  ///< removed by 301 (the running one included)
  std::uint64_t ik_failures = 0;    ///< Cartesian steps without an IK solution (no motion)
  std::uint64_t dropped_outs = 0;   ///< faults that fired, one counter each
  std::uint64_t suppressed_replies = 0;
  std::uint64_t garbage_replies = 0;
  std::uint64_t corrupt_replies = 0;
  std::uint64_t wrong_command_replies = 0;
  std::uint64_t cycles = 0;        ///< 10 ms cycles run
  std::uint64_t silent_drops = 0;  ///< packets lost to a silent period
  std::uint64_t delayed_lost = 0;  ///< motion packets lost to a full latency queue
};

}  // namespace orthoflow::simulation
