#pragma once
/// @file
/// @brief JacoController: the JACO driver's control loop (issue 19, specs/JACO.md 10 and 11) and
/// the safety monitor's seat (issue 49, docs/SAFETY.md). One thread calls cycle() every 10 ms (the
/// arm's period; JacoArm does it); a guard calls guard() every few milliseconds from a thread that
/// never touches USB; any thread submits commands, reads the newest snapshot and pulls the stop.
///
/// Each cycle: read the joints and fingers (command 15, plus a rotating slow read: sensors,
/// currents, arm state), then let the active mode say what the next period would do:
/// - a joint move or a pose (IK to the solution nearest the current joints) is streamed as 100 Hz
///   angular velocity points along a synchronised trapezoid (jaco_motion.hpp), never as position
///   points, which the arm would finish even if the host died;
/// - HOME / RETRACT press and release the virtual button (next_button_action, JACO.md 10.1), with
///   the DSP >= 5 double send 100 ms apart (JACO.md 9): the firmware drives the arm;
/// - a client-streamed joint velocity is sent as it is;
/// - the fingers' goal becomes a finger velocity;
/// and the safety monitor (jaco_safety_monitor.hpp) checks that next state and its stopping
/// envelope for the whole arm, every cycle, in every mode, idle included. Only then is a packet
/// sent; a violation stops the arm (StopReason::SAFETY) and is kept in the snapshot.
///
/// Stops, on every path:
/// - submit() refuses a command the monitor refuses along its whole path (an early, named refusal);
/// - watchdog: a motion needs a command or keep_alive() at least every command_timeout (100 ms);
///   the cycle that could not send again before that deadline releases and erases;
/// - estop() (any thread, wait-free, async-signal-safe) latches: no motion packet leaves after it,
///   the next chance on the USB thread releases the joystick and erases the FIFO, and every cycle
///   erases again until reset_estop(); every motion command is refused meanwhile;
/// - guard(): an arm that has not answered for silence_fault_ns is FAULT in the snapshot at once
///   (bound: period + the link's transfer budget, docs/SAFETY.md), whatever the USB thread is
///   doing;
/// - a failed exchange (unplug, stall, bad reply) puts the controller in FAULT in that same cycle:
///   a best-effort stop is sent unless the arm is gone, and every command is refused until
///   reinitialise().
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>

#include "core/result.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_link.hpp"
#include "drivers/jaco/jaco_motion.hpp"
#include "drivers/jaco/jaco_safety.hpp"
#include "drivers/jaco/jaco_safety_monitor.hpp"

namespace orthoflow::drivers::jaco {

/// @brief What the controller is doing.
enum class ControlState : std::uint8_t { IDLE, MOVING, VELOCITY, HOMING, ESTOP, FAULT };
[[nodiscard]] const char* to_string(ControlState state) noexcept;

/// @brief Why the last motion ended.
enum class StopReason : std::uint8_t {
  NONE,
  REACHED,
  STOPPED,
  WATCHDOG,
  ESTOP,
  FAULT,
  SETTLE_TIMEOUT,
  HOME_TIMEOUT,
  REFUSED,
  SAFETY  ///< the safety monitor stopped it: see ArmSnapshot::violation
};
[[nodiscard]] const char* to_string(StopReason reason) noexcept;

/// @brief A command from a client. Fields not used by `kind` are ignored.
struct ArmCommand {
  enum class Kind : std::uint8_t {
    KEEP_ALIVE,    ///< "still here": feeds the watchdog
    MOVE_JOINTS,   ///< joints: actuator degrees
    MOVE_POSE,     ///< pose: metres / radians (JACO.md 8)
    VELOCITY,      ///< velocity: deg/s, streamed by the client at up to 100 Hz
    MOVE_FINGERS,  ///< fingers: targets in the model's units (0 open)
    HOME,
    RETRACT,
    STOP,  ///< stop now (not latched)
  };
  Kind kind = Kind::KEEP_ALIVE;
  JointAngles joints{};
  CartesianPose pose{};
  JointVelocity velocity{};
  std::array<double, FINGERS> fingers{};
  double speed_fraction = 1.0;  ///< of the speed cap, in (0, 1]
};

/// @brief Tuning. Defaults follow JACO.md 9 and issue 19.
struct ControllerOptions {
  SafetyLimits limits{};
  LinkPolicy link{};
  std::int64_t command_timeout_ns = 100'000'000;  ///< watchdog
  double gain_per_s = 4.0;                        ///< position correction while streaming
  double goal_tolerance_deg = 0.1;
  double finger_tolerance = 0.01;  ///< of the finger range
  /// Fingers that travel less than this share of their range for finger_stall_ns have stopped
  /// against something (a grasped object): the finger goal ends there (fingers_blocked).
  double finger_stall_travel = 0.005;
  std::int64_t finger_stall_ns = 300'000'000;
  std::int64_t settle_timeout_ns = 2'000'000'000;  ///< after the profile ends
  std::int64_t home_timeout_ns = 30'000'000'000;   ///< HOME / RETRACT (from far: about 15 s)
  /// Where the firmware drives the arm for HOME and RETRACT (the monitor's envelope of that motion;
  /// the real arm's RETRACT is a setting of its own: docs/SAFETY.md).
  JointAngles home_joints = HOME_JOINTS;
  JointAngles retract_joints{270.0, 210.0, 30.0, 270.0, 90.0, 90.0};
  /// No reply for this long is a FAULT (guard()): one period plus the link's transfer budget.
  std::int64_t silence_fault_ns = 26'000'000;
  std::int64_t double_send_gap_ns = 100'000'000;  ///< DSP >= 5 joystick quirk
};

/// @brief Everything known about the arm after a cycle. Plain data; copied under a mutex.
struct ArmSnapshot {
  std::int64_t stamp_ns = 0;  ///< transport clock when the joints were read
  std::uint64_t cycle = 0;
  JointAngles joints{};
  JointVelocity velocity{};  ///< from successive readings, deg/s
  /// The same over the oldest reading kept (at least 50 ms when there is one): a step miscounted
  /// is a fifth at most, so the firmware's speed is judged on it, not on `velocity`.
  JointVelocity span_velocity{};
  JointVelocity commanded{};  ///< the last velocity point sent, deg/s
  std::array<double, FINGERS> fingers{};
  bool fingers_moving = false;   ///< a finger goal is under way
  bool fingers_blocked = false;  ///< the last finger goal ended short: the fingers stalled against
                                 ///< something (ControllerOptions::finger_stall_ns)
  CartesianPose pose{};          ///< forward kinematics of `joints`
  std::array<float, JOINTS> currents{};
  SensorInfo sensors{};
  ArmState arm_state = ArmState::NOINIT;
  ControlState control = ControlState::IDLE;
  StopReason last_stop = StopReason::NONE;
  bool estop = false;
  bool fault = false;
  JacoError fault_error{};
  std::uint64_t watchdog_stops = 0;
  std::uint64_t refused = 0;
  std::uint64_t points_sent = 0;
  std::uint64_t cycles_overrun = 0;  ///< cycles whose exchanges took longer than the period
  SafetyViolation violation{};       ///< what the monitor found when last_stop is SAFETY
  std::uint64_t monitor_stops = 0;   ///< motions the monitor stopped
  std::uint64_t monitor_nodes = 0;   ///< stretches the monitor examined in the last cycle
  std::int64_t last_reply_ns = 0;    ///< when the arm last answered (transport clock)
  std::int64_t stop_request_ns = 0;  ///< when the current stop latch was requested
  std::int64_t stop_sent_ns = 0;     ///< when its release + erase reached the wire (0: not yet)
  HeldCapsule held{};                ///< what the monitor counts the hand holding
};

class JacoController {
 public:
  /// @brief Opens the arm, reads its identity, takes API control, selects angular control,
  /// releases the joystick and erases the FIFO (nothing a previous session left can move it).
  /// @pre @p transport outlives the controller; the calling thread becomes the USB thread.
  [[nodiscard]] static Result<std::unique_ptr<JacoController>, JacoError> open(
      UsbTransport& transport, const UsbDeviceInfo& device, ControllerOptions options = {});
  /// @brief Stops any motion, releases API control. @pre Called on the USB thread.
  ~JacoController();
  JacoController(const JacoController&) = delete;
  JacoController& operator=(const JacoController&) = delete;

  /// @brief Validates and queues @p command (any thread). The newest motion command replaces a
  /// queued one. @return REFUSED naming the limit, ESTOP, FAULT, INVALID_STATE. @note Accepted
  /// commands feed the watchdog; refused ones do not.
  [[nodiscard]] Result<void, JacoError> submit(const ArmCommand& command);
  /// @brief Feeds the watchdog (any thread, wait-free).
  void keep_alive() noexcept;
  /// @brief Latches the emergency stop (any thread, wait-free, async-signal-safe): from now on no
  /// motion packet leaves; the USB thread releases and erases at its next chance.
  void estop() noexcept {
    if (!estop_.exchange(true, std::memory_order_acq_rel))
      estop_request_ns_.store(clock_->now_ns(), std::memory_order_release);
  }
  /// @brief The guard's tick (any thread, never blocks on USB; JacoArm runs it every 2 ms): an arm
  /// silent for silence_fault_ns is FAULT in the snapshot now, and no packet but a stop leaves.
  void guard(std::int64_t now_ns) noexcept;
  /// @brief What the hand holds from now on, for the monitor (the task runner sets it at a grasp
  /// and clears it at a release). @pre finite values.
  void set_held(const HeldCapsule& held);
  /// @brief Clears the latch once the arm is stopped. @return FAULT if the link failed meanwhile.
  [[nodiscard]] Result<void, JacoError> reset_estop();
  /// @brief One control period (USB thread only). Never throws; never allocates.
  void cycle() noexcept;
  /// @brief After a FAULT: open the device again (a re-plugged arm: enumerate first and pass the
  /// new @p device) and run the start-up again. @pre USB thread.
  [[nodiscard]] Result<void, JacoError> reinitialise(const UsbDeviceInfo& device);

  /// @brief A copy of the newest snapshot (any thread). @pre none.
  [[nodiscard]] ArmSnapshot snapshot() const;
  [[nodiscard]] const ArmIdentity& identity() const noexcept { return identity_; }
  [[nodiscard]] const ControllerOptions& options() const noexcept { return options_; }
  [[nodiscard]] const LinkStats& link_stats() const noexcept { return link_->stats(); }
  [[nodiscard]] std::int64_t now_ns() const noexcept { return clock_->now_ns(); }

 private:
  JacoController(UsbTransport& transport, ControllerOptions options) noexcept;
  Result<void, JacoError> start_up(const UsbDeviceInfo& device);
  /// @p proof: where HOME / RETRACT's whole motion was proven clear (those two only).
  Result<void, JacoError> validate(const ArmCommand& command, const ArmSnapshot& now,
                                   FirmwareProof* proof = nullptr) const;
  Result<ArmCommand, JacoError> check_command(const ArmCommand& command, FirmwareProof* proof,
                                              const ArmSnapshot& now) const;
  void read_state() noexcept;
  void run_motion(std::int64_t now) noexcept;
  void run_homing(std::int64_t now) noexcept;
  void run_modes(std::int64_t now) noexcept;
  void start_pending(std::int64_t now) noexcept;
  bool send_joystick(const JoystickState& state) noexcept;
  bool send_velocity(const JointVelocity& joints,
                     const std::array<double, FINGERS>& fingers) noexcept;
  void stop_arm(StopReason reason) noexcept;
  void fail(const JacoError& error) noexcept;
  /// The monitor's gate: true when the next period may run @p v (and the fingers); otherwise the
  /// arm has been stopped with the violation kept.
  bool monitor_allows(const JointVelocity& v, bool firmware) noexcept;
  /// A stop was latched or a fault declared by another thread: nothing but a stop may leave.
  [[nodiscard]] bool halted() const noexcept;
  void latch_estop() noexcept;
  void publish() noexcept;
  std::array<double, FINGERS> finger_velocity() const noexcept;
  /// True once the fingers have made no progress for finger_stall_ns (marks progress otherwise).
  bool fingers_stalled(std::int64_t now) noexcept;

  UsbTransport* transport_;
  const MonotonicClock* clock_;
  ControllerOptions options_;
  std::optional<JacoLink> link_;
  ArmIdentity identity_{};

  // Shared with client threads (mutex_ guards pending_* and published_).
  mutable std::mutex mutex_;
  std::optional<ArmCommand> pending_motion_;
  std::optional<ArmCommand> pending_fingers_;
  bool pending_stop_ = false;
  ArmSnapshot published_{};
  std::atomic<bool> estop_{false};
  std::atomic<std::int64_t> estop_request_ns_{0};
  std::atomic<std::int64_t> last_client_ns_{0};
  std::atomic<std::int64_t> last_reply_ns_{0};
  std::atomic<bool> silent_{false};  ///< set by guard(): the arm stopped answering
  std::atomic<bool> linked_{false};  ///< start-up done: the guard watches
  HeldCapsule held_{};               ///< guarded by mutex_; copied into state_ each cycle
  FirmwareProof firmware_proof_{};   ///< guarded by mutex_: the accepted HOME / RETRACT's proof

  // USB thread only.
  ArmSnapshot state_{};
  ArmCommand active_{};
  JointProfile profile_{};
  std::int64_t motion_start_ns_ = 0;
  JointVelocity last_velocity_{};
  std::optional<std::array<double, FINGERS>> finger_goal_;
  std::array<double, FINGERS> finger_mark_{};  ///< where the fingers were at finger_mark_ns_
  std::int64_t finger_mark_ns_ = 0;            ///< the fingers' last progress
  bool button_pressed_ = false;
  std::int64_t button_sent_ns_ = 0;
  bool button_resent_ = false;
  bool joystick_dirty_ = false;  ///< a non-release joystick state may be latched in the arm
  bool have_previous_ = false;
  struct Reading {
    std::int64_t t_ns = 0;
    JointAngles q{};
  };
  std::array<Reading, 8> readings_{};  ///< the newest joint readings, for the velocity
  std::size_t reading_next_ = 0;
};

}  // namespace orthoflow::drivers::jaco
