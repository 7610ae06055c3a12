#pragma once
/// @file
/// @brief The JACO's safety monitor (docs/SAFETY.md; STYLE rule 20): one check that every way of
/// moving the arm passes, every control cycle, before anything is sent. A motion mode (a streamed
/// move, a client's velocity stream, the fingers, the HOME / RETRACT button the firmware drives)
/// only says what the next cycle would do (CycleIntent); check_cycle() decides whether the whole
/// arm, from that next state braked to rest, stays inside every limit. Otherwise the controller
/// stops the arm (velocity zero, FIFO erased, joystick released) and reports the violation.
///
/// What is checked, against SafetyLimits:
/// - every value finite; the commanded speed under the cap (host motion) or the measured speed
///   under the hardware's (firmware motion); a commanded speed-up under the acceleration cap
///   (slowing down is never refused);
/// - the stopping envelope: the arm keeps its measured velocity for the command latency, runs the
///   command for one period, then brakes at brake_decel to rest (envelope_range()). The real arm
///   brakes at least that hard and speeds up no faster than at once, so each joint stays within
///   the envelope's range: the joints stay inside their limits there, and the whole body (links,
///   hand, fingers at their widest this cycle, a held object) stays inside the workspace and out
///   of every keep-out for every configuration in that box of joint ranges;
/// - the box is swept, not sampled: every capsule's motion within a box is bounded from its middle
///   (sweep_bounds, jaco_body.hpp), so a box whose middle body is clear by those bounds is clear
///   everywhere; one that is not is halved along its widest joint until its half-turns move the
///   body less than sweep_resolution_m, and one still not clear is a violation.
/// A straight move (check_joint_move) is swept the same way along its segment.
/// Work is bounded: at most MAX_MONITOR_NODES stretches per cycle's check (about 2.6 us each on
/// the bench machine, bench/RESULTS.md); a motion not shown clear within them is refused as
/// UNPROVEN (fast motion near a keep-out: slow down). The firmware's own motion (HOME, RETRACT) is
/// proven whole before it starts (prove_firmware_motion, MAX_FIRMWARE_NODES, on the submitting
/// thread); each of its cycles then only checks that the arm stays inside what was proven. Pure;
/// no allocation; deterministic.
#include <cstddef>

#include "core/result.hpp"
#include "drivers/jaco/jaco_body.hpp"
#include "drivers/jaco/jaco_motion.hpp"
#include "drivers/jaco/jaco_safety.hpp"

namespace orthoflow::drivers::jaco {

/// @brief The stretches of motion one check may examine.
inline constexpr std::size_t MAX_MONITOR_NODES = 1024;
/// @brief The stretches the proof of a whole firmware motion may examine (once, at submit).
inline constexpr std::size_t MAX_FIRMWARE_NODES = 8192;

/// @brief A firmware motion proven clear as a whole: every configuration in [lo, hi] with the
/// fingers no wider than finger_open and this held object.
struct FirmwareProof {
  bool valid = false;
  JointAngles lo{}, hi{};
  double finger_open = 0.0;
  HeldCapsule held{};
};

/// @brief What the next control cycle would do: every motion mode reduces to this.
struct CycleIntent {
  JointAngles joints{};      ///< measured at the cycle's start (deg)
  JointVelocity velocity{};  ///< measured (deg/s)
  /// Measured over a longer span (ArmSnapshot::span_velocity) when span_measured: what a firmware
  /// cycle's speed is judged on (the envelope still uses `velocity`).
  JointVelocity span_velocity{};
  bool span_measured = false;
  JointVelocity command{};   ///< what this cycle streams (deg/s); firmware motion: the measured
  JointVelocity previous{};  ///< what the last cycle streamed (deg/s)
  bool firmware = false;     ///< HOME / RETRACT: the arm drives itself (hardware speed bounds)
  /// Firmware motion: where the firmware drives the joints (HOME or RETRACT); each joint is taken
  /// to move monotonically toward it (docs/SAFETY.md: an assumption the real arm must confirm).
  JointAngles firmware_goal{};
  double finger_open = 0.0;  ///< the widest opening the fingers reach this cycle (0 .. 1)
  HeldCapsule held{};        ///< what the hand holds (tool frame)
};

/// @brief An interval of one joint, in degrees.
struct JointRange {
  double lo = 0.0;
  double hi = 0.0;
};

/// @brief The range joint @p j stays in over the stopping envelope of @p intent (the model of the
/// file comment). @pre finite intent; brake_decel > 0.
[[nodiscard]] JointRange envelope_range(const SafetyLimits& limits, const CycleIntent& intent,
                                        std::size_t j) noexcept;

/// @brief Work a check did (for the benchmark and the telemetry).
struct MonitorCost {
  std::size_t nodes = 0;  ///< stretches examined
};

/// @brief Checks the next cycle as the file comment says. @return the first violation found.
/// @pre limits.geometry set; period > 0.
/// A firmware cycle (intent.firmware) inside a valid @p proof (its joints within the proof's box by
/// half a degree, the same held object, the fingers no wider) needs no sweep: the rates are
/// checked.
[[nodiscard]] Result<void, SafetyViolation> check_cycle(
    const SafetyLimits& limits, const CycleIntent& intent, MonitorCost* cost = nullptr,
    const FirmwareProof* proof = nullptr) noexcept;

/// @brief Checks a straight joint-space move from @p from to @p to (the path a streamed move
/// follows) with the fingers at @p finger_open and @p held: finite values, the target inside the
/// joint limits, and the whole body clear along the whole path, swept as check_cycle sweeps. The
/// controller runs it when a move is submitted and again when it starts (an early, named refusal);
/// check_cycle is what guards every cycle of it. @pre none.
[[nodiscard]] Result<void, SafetyViolation> check_joint_move(
    const SafetyLimits& limits, const JointAngles& from, const JointAngles& to,
    double finger_open = 0.0, const HeldCapsule& held = {}, MonitorCost* cost = nullptr) noexcept;

/// @brief Checks the firmware's own motion (HOME, RETRACT) from @p from to @p goal before it
/// starts: each joint is taken to move monotonically toward its goal (docs/SAFETY.md), so the whole
/// box of joint ranges between the two must be clear, swept as check_cycle sweeps. Once started,
/// the firmware runs to its pose even if the link fails (the virtual button stays latched in the
/// arm), so the host starts it only when all of it is proven clear. @pre none.
[[nodiscard]] Result<FirmwareProof, SafetyViolation> prove_firmware_motion(
    const SafetyLimits& limits, const JointAngles& from, const JointAngles& goal,
    double finger_open = 0.0, const HeldCapsule& held = {}, MonitorCost* cost = nullptr) noexcept;

/// @brief Distance in degrees joint @p j travels braking from @p speed at @p decel. @pre decel > 0.
[[nodiscard]] inline double braking_distance_deg(double speed, double decel) noexcept {
  return speed * speed / (2.0 * decel);
}

}  // namespace orthoflow::drivers::jaco
