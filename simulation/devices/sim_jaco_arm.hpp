#pragma once
/// @file
/// @brief SimJacoArm: one simulated Kinova JACO (v1 or JACO2, 6 joints, 3 fingers) implementing the
/// documented protocol of specs/JACO.md (sections 3-11) and specs/USB_TESTING.md 3.3 on simulated
/// time, so the JACO driver is tested on a machine without USB. It has never been compared with a
/// real arm: it is exactly as right as the brief it implements. Where the brief is unsure it makes
/// a documented choice (marked [I]), so a driver passing against it can still fail on hardware.
/// Transport-independent: a host (SimUsbHost through SimJacoUsbDevice, or the libusb shim of
/// tests/support/sim_libusb) hands it every OUT packet and takes its replies for the IN endpoint.
/// Its configuration and counters: sim_jaco_config.hpp. Packets are built and parsed with
/// drivers/jaco/jaco_protocol.hpp.
///
/// Transactions (JACO.md 4):
/// - every OUT packet the arm understands queues one reply for the next IN, in a FIFO of
///   SIM_JACO_REPLY_QUEUE replies (when full, the oldest is lost and counted) [I];
/// - every reply echoes the request's command id and id_packet; packet_quantity is 1 and
///   command_size the bytes of data the reply carries [I];
/// - an unknown command id (44 included, and 62 on DSP < 5) gets no reply: the next IN times out
///   [I]; sets answer an ack (the header with command_size 0), also when they are ignored.
/// Replies:
/// - 15 / 105: true joints (deg) and fingers; 107: commanded joints (the running or next queued
///   angular position point's target, the HOME / RETRACT pose while the button drives the arm,
///   else the true joints);
/// - 104: pose (m, rad) and fingers, updated only in Cartesian control mode (JACO.md 8): in angular
///   mode it keeps the last pose computed in Cartesian mode (at power-on: the start pose's) [I];
///   106: the running or next Cartesian point's target, else the pose of the commanded joints;
/// - 114: joint velocities (deg/s) and finger velocities; on DSP < 5 positions, as 15 (JACO.md 5);
/// - 108 / 109 / 110 / 113 / 111: the config's constant, noise-free values; 36: the firmware;
/// - 1: client-info slice id_packet of 55 (slices 1-2 the five strings; 3-55 every byte the slice
///   number [I]); 200: arm-info slice of 19 (the same filler; slice 2 has the retract mode as int32
///   at body bytes 52-55); a slice outside the range has a zero body [I];
/// - 62 (DSP >= 5 only): encode_arm_status of the state, fingers initialised (1 once out of
///   NOINIT), API control, force control, torque sensors (JACO2 only) [I: polarity unknown].
/// Commands:
/// - 302 / 303 switch API control. Without it 305 and 308 are ignored (counted); 308 also while
///   NOINIT [I]. 303 only clears the flag: queued points and a latched joystick keep acting [I,
///   the strict choice];
/// - 47 / 49 select angular / Cartesian mode (power-on: angular [I]); 57 / 58 force control (JACO2
///   only: v1 has no torque sensors; stored, no effect on motion); 301 empties the FIFO, drops the
///   running point and stops the fingers where they are.
/// Joystick (305, JACO.md 6.2, 10.1), latched until the next 305:
/// - button 2 drives the retract state machine. A press (0 -> 1) from NOINIT / NORMAL /
///   NORMAL_TO_READY heads HOME (NORMAL_TO_READY); from RETRACT_STANDBY heads HOME
///   (RETRACT_TO_READY); from READY_STANDBY heads RETRACT (READY_TO_RETRACT); in READY_TO_RETRACT /
///   RETRACT_TO_READY (stopped by a release) it reverses. The arm moves only while the button stays
///   latched, each joint at its top speed, and reaches READY_STANDBY / RETRACT_STANDBY at the pose;
///   a release stops it in the moving state. Held at HOME for held_home_to_retract_ns it goes on to
///   RETRACT [I, from JACO.md 10.1 "if the state flips to READY_TO_RETRACT"]. NOINIT is left for
///   good by the first press. While button 2 is latched nothing else moves;
/// - nonzero axes (clamped to [-1, 1], JACO.md 11) move the arm and pause the FIFO. Angular mode:
///   axis i drives joint i + 1 at the axis value times its top speed. Cartesian mode: axes 0-2 the
///   linear velocity along base x, y, z (times max_linear_speed), the wrist axes the angular
///   velocity about base x (forth/back), y (left/right), z (rotation) (times max_angular_speed);
///   DSP >= 5 reads wrist left/right on axis 3 and forth/back on 4, DSP < 5 the swapped pair with
///   axis 5 negated (JACO.md 6.2) [I]. A Cartesian step solves the IK of the pose one cycle ahead.
/// Trajectory FIFO (308, JACO.md 6.1, 9, 11): TRAJECTORY_FIFO points; one arriving at a full FIFO
/// is acked but dropped (counted). The head runs on the 10 ms cycle, in either control mode [I]:
/// - angular position: each joint at its top speed until joints and (hand mode 1) fingers are at
///   their targets, then it pops, so every point takes at least one cycle; angles are literal (no
///   wrapping). Cartesian position: solved once by inverse_kinematics (seeded with the current
///   joints) when it reaches the head, then as angular. A target outside jaco_joint_limits() or
///   without an IK solution is dropped (points_rejected);
/// - velocity (type 7: m/s and rad/s in the base frame, type 8: deg/s): exactly one cycle each,
///   clamped to the top speeds; TIME_DELAY holds delay_s; NO_MOVEMENT one cycle;
/// - hand mode 1 sets the finger targets (kept after the pop: fingers move toward them at
///   finger_speed); 2 moves the fingers at the given speed while the point runs.
/// Dynamics: no acceleration limit (speeds jump); joints clamp at the limits, fingers to [0,
/// finger_max]. Any motion not driven by button 2 puts an initialised arm in NORMAL. step(now) runs
/// every 10 ms cycle due by now (the first 10 ms after power-on); a packet acts from the next
/// cycle. Thread safety: none; one host thread drives it. Determinism: given the packets and their
/// times, every reply byte is a function of the config (faults draw from a core::Rng seeded by
/// fault_seed, one draw per enabled fault per packet in a fixed order).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "core/rng.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_protocol.hpp"
#include "simulation/devices/sim_jaco_config.hpp"

namespace orthoflow::simulation {

/// @brief One simulated JACO. @note Not copyable; allocates nothing after construction (the FIFO
/// and the reply queue are fixed arrays): hold it in a unique_ptr (about 110 KB).
class SimJacoArm {
 public:
  /// @brief Power-on at @p start_ns (the first cycle runs at start_ns + 10 ms).
  /// @pre Client strings of at most 19 chars, a start state listed in SimJacoConfig, finite poses,
  /// speeds > 0, rates in [0, 1] (OF_ENFORCE).
  explicit SimJacoArm(SimJacoConfig config, std::int64_t start_ns = 0);
  SimJacoArm(const SimJacoArm&) = delete;
  SimJacoArm& operator=(const SimJacoArm&) = delete;

  [[nodiscard]] const SimJacoConfig& config() const noexcept { return config_; }

  // ---- host side ------------------------------------------------------------------------------
  /// @brief Runs every 10 ms cycle due at or before @p now_ns. Earlier times are a no-op.
  void step(std::int64_t now_ns) noexcept;
  /// @brief The arm receives OUT packet @p packet at @p now_ns (steps to it first).
  void receive(std::span<const std::byte, drivers::jaco::PACKET_BYTES> packet,
               std::int64_t now_ns) noexcept;
  /// @brief True if a reply waits for the IN endpoint.
  [[nodiscard]] bool has_reply() const noexcept { return reply_count_ > 0; }
  /// @brief Pops the oldest reply. @pre has_reply() (OF_ENFORCE).
  [[nodiscard]] drivers::jaco::Packet take_reply() noexcept;
  /// @brief Drops every pending reply (a replug or port reset), counted as lost; then queues the
  /// stale_replies fault's replies again.
  void reset_replies() noexcept;
  /// @brief Power loss and power-on at @p now_ns: the config's start state, pose, empty FIFO,
  /// released joystick, no API control; the fault Rng and the counters keep going.
  void power_cycle(std::int64_t now_ns) noexcept;

  // ---- ground truth for tests -----------------------------------------------------------------
  [[nodiscard]] const drivers::jaco::JointAngles& joints() const noexcept { return joints_; }
  /// @brief Joint speeds of the last cycle (deg/s).
  [[nodiscard]] const std::array<double, drivers::jaco::JOINTS>& joint_velocities() const noexcept {
    return velocity_;
  }
  [[nodiscard]] const std::array<double, drivers::jaco::FINGERS>& fingers() const noexcept {
    return fingers_;
  }
  [[nodiscard]] std::size_t fifo_size() const noexcept { return fifo_size_; }
  [[nodiscard]] const drivers::jaco::JoystickState& joystick() const noexcept { return joystick_; }
  /// @brief True if a joint moved in the last cycle.
  [[nodiscard]] bool moving() const noexcept;
  /// @brief End of the last cycle in which a joint moved; nullopt if none ever did.
  [[nodiscard]] std::optional<std::int64_t> last_motion_ns() const noexcept {
    return last_motion_ns_;
  }
  [[nodiscard]] bool api_control() const noexcept { return api_control_; }
  [[nodiscard]] bool force_control() const noexcept { return force_control_; }
  [[nodiscard]] SimJacoControlMode control_mode() const noexcept { return mode_; }
  [[nodiscard]] drivers::jaco::ArmState state() const noexcept { return state_; }
  /// @brief The pose command 104 reports now (updated only in Cartesian mode).
  [[nodiscard]] const drivers::jaco::CartesianPose& reported_pose() const noexcept { return pose_; }
  [[nodiscard]] const SimJacoCounters& counters() const noexcept { return counters_; }
  /// @brief The arm's time: the last step() or receive() time.
  [[nodiscard]] std::int64_t now_ns() const noexcept { return now_ns_; }
  [[nodiscard]] double finger_max() const noexcept { return finger_max_; }
  /// @brief Something rigid between the fingers (a grasped object, for a test or a simulated
  /// world): no finger closes past @p finger (model units; 0 open) while it is there; they still
  /// open. nullopt: nothing between them.
  void set_finger_stop(std::optional<double> finger) noexcept { finger_stop_ = finger; }

 private:
  enum class Head : std::uint8_t { NONE, POSITION, VELOCITY, DELAY, IDLE };

  void power_on(std::int64_t now_ns) noexcept;
  void handle(std::span<const std::byte, drivers::jaco::PACKET_BYTES> packet,
              drivers::jaco::PacketHeader header,
              std::optional<drivers::jaco::Packet>& reply) noexcept;
  bool setting_command(drivers::jaco::Command command) noexcept;
  void motion_command(drivers::jaco::Command command,
                      std::span<const std::byte, drivers::jaco::PACKET_BYTES> packet) noexcept;
  void joystick_command(std::span<const std::byte, drivers::jaco::PACKET_BYTES> packet) noexcept;
  void trajectory_command(std::span<const std::byte, drivers::jaco::PACKET_BYTES> packet) noexcept;
  void press_home_button() noexcept;
  void erase() noexcept;
  void queue_reply(drivers::jaco::Packet reply) noexcept;
  void apply_reply_faults(std::optional<drivers::jaco::Packet>& reply,
                          std::uint16_t command) noexcept;
  [[nodiscard]] bool fault(double rate) noexcept;
  [[nodiscard]] std::optional<drivers::jaco::Packet> state_reply(
      drivers::jaco::Command command, drivers::jaco::PacketHeader header) const noexcept;
  [[nodiscard]] drivers::jaco::Packet slice_reply(
      drivers::jaco::Command command, drivers::jaco::PacketHeader header) const noexcept;
  [[nodiscard]] drivers::jaco::JointAngles commanded_joints() const noexcept;
  [[nodiscard]] std::optional<drivers::jaco::CartesianPose> commanded_pose() const noexcept;
  [[nodiscard]] drivers::jaco::CartesianPose pose_of(
      const drivers::jaco::JointAngles& joints) const noexcept;

  [[nodiscard]] bool inside_limits(const drivers::jaco::JointAngles& angles) const noexcept;
  void cycle(std::int64_t t_ns) noexcept;
  void run_button(std::int64_t t_ns) noexcept;
  bool run_axes() noexcept;
  void run_fifo(std::int64_t t_ns) noexcept;
  void finish_head(std::int64_t t_ns) noexcept;
  bool start_head(std::int64_t t_ns) noexcept;
  Head head_of(const drivers::jaco::TrajectoryPoint& point, std::int64_t t_ns) noexcept;
  void pop_head() noexcept;
  bool move_toward(const drivers::jaco::JointAngles& target) noexcept;
  void move_velocity(const std::array<double, drivers::jaco::JOINTS>& deg_s) noexcept;
  void integrate() noexcept;
  void run_delayed(std::int64_t t_ns) noexcept;
  [[nodiscard]] bool silent(std::int64_t t_ns) const noexcept;
  void cartesian_step(const Eigen::Vector3d& linear, const Eigen::Vector3d& angular) noexcept;
  void move_fingers() noexcept;

  SimJacoConfig config_;
  core::Rng rng_;
  drivers::jaco::JointLimits limits_;
  const drivers::jaco::ArmGeometry* geometry_;  // the model's DH geometry
  double finger_max_ = 0.0;
  double finger_speed_ = 0.0;
  std::int64_t now_ns_ = 0;
  std::int64_t next_cycle_ns_ = 0;

  drivers::jaco::ArmState state_ = drivers::jaco::ArmState::NOINIT;
  bool api_control_ = false;
  bool force_control_ = false;
  SimJacoControlMode mode_ = SimJacoControlMode::ANGULAR;
  drivers::jaco::JointAngles joints_{};
  std::array<double, drivers::jaco::JOINTS> velocity_{};
  std::array<double, drivers::jaco::JOINTS> desired_{};  // this cycle's velocity command
  std::optional<drivers::jaco::JointAngles> toward_{};   // a position the joints stop exactly at
  struct Delayed {
    std::int64_t due_ns = 0;
    drivers::jaco::Packet packet{};
  };
  // Motion packets in flight (command latency): room for a whole FIFO's worth and then some.
  std::array<Delayed, drivers::jaco::TRAJECTORY_FIFO + 64> delayed_{};
  std::size_t delayed_head_ = 0;
  std::size_t delayed_count_ = 0;
  std::array<double, drivers::jaco::FINGERS> fingers_{};
  std::array<double, drivers::jaco::FINGERS> finger_velocity_{};
  std::array<double, drivers::jaco::FINGERS> finger_target_{};
  std::optional<double> finger_stop_{};  ///< set_finger_stop
  drivers::jaco::CartesianPose pose_{};
  std::optional<std::int64_t> last_motion_ns_{};

  drivers::jaco::JoystickState joystick_{};
  std::optional<std::int64_t> last_joystick_ns_{};
  bool transition_ = false;  // button 2 drives the arm toward transition_target_
  drivers::jaco::JointAngles transition_target_{};
  std::optional<std::int64_t> standby_since_ns_{};  // reached HOME with the button held

  std::array<drivers::jaco::TrajectoryPoint, drivers::jaco::TRAJECTORY_FIFO> fifo_{};
  std::size_t fifo_head_ = 0;
  std::size_t fifo_size_ = 0;
  Head head_ = Head::NONE;
  drivers::jaco::JointAngles head_target_{};
  std::optional<drivers::jaco::CartesianPose> head_pose_{};  // a Cartesian position point's target
  std::int64_t head_until_ns_ = 0;
  bool head_finger_velocity_ = false;  // hand mode 2: fingers at head_finger_speed_
  std::array<double, drivers::jaco::FINGERS> head_finger_speed_{};
  bool head_ran_ = false;  // the head ran this cycle (not paused by the axes)

  std::array<drivers::jaco::Packet, SIM_JACO_REPLY_QUEUE> replies_{};
  std::size_t reply_head_ = 0;
  std::size_t reply_count_ = 0;
  SimJacoCounters counters_{};
};

}  // namespace orthoflow::simulation
