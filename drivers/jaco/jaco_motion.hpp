#pragma once
/// @file
/// @brief JointProfile: the synchronised trapezoidal joint-space profile the JACO driver streams as
/// 100 Hz angular velocity points. Every joint starts and ends together; no joint exceeds the speed
/// or acceleration cap. The driver adds a bounded proportional correction on the measured position
/// (velocity_command), so the arm converges on the target even if it lags the profile.
///
/// Why velocity streaming instead of position trajectory points: a position point, once queued,
/// runs to completion even if the host dies (JACO.md 11), while a velocity point moves the arm for
/// one 10 ms period only. Streaming keeps every motion under the driver's watchdog.
/// Pure; never allocates; deterministic.
#include <array>

#include "drivers/jaco/jaco_kinematics.hpp"
#include "drivers/jaco/jaco_protocol.hpp"

namespace orthoflow::drivers::jaco {

using JointVelocity = std::array<double, JOINTS>;

/// @brief A planned move from start to goal. Default-constructed: no motion.
class JointProfile {
 public:
  JointProfile() = default;
  /// @brief Plans @p start -> @p goal with per-joint caps @p max_speed (deg/s) and @p max_accel
  /// (deg/s^2). @pre Both caps > 0, finite angles (the safety layer checked them).
  JointProfile(const JointAngles& start, const JointAngles& goal, double max_speed,
               double max_accel) noexcept;
  /// @brief Seconds from start to goal. @pre none.
  [[nodiscard]] double duration_s() const noexcept { return duration_; }
  /// @brief Planned position at @p t_s (clamped to [0, duration]). @pre none.
  [[nodiscard]] JointAngles position(double t_s) const noexcept;
  /// @brief Planned velocity at @p t_s (0 outside [0, duration]). @pre none.
  [[nodiscard]] JointVelocity velocity(double t_s) const noexcept;
  [[nodiscard]] const JointAngles& goal() const noexcept { return goal_; }

 private:
  JointAngles start_{};
  JointAngles goal_{};
  double duration_ = 0.0;
  double accel_time_ = 0.0;  ///< seconds of the ramp at each end
  double peak_ = 0.0;        ///< peak of the normalised speed s'(t) (1/s), s from 0 to 1
};

/// @brief The velocity to stream at @p t_s: the profile's plus gain * (planned - measured),
/// clamped so no joint exceeds @p max_speed nor changes by more than @p max_accel * dt from
/// @p previous. @pre dt_s > 0, caps > 0.
[[nodiscard]] JointVelocity velocity_command(const JointProfile& profile, double t_s,
                                             const JointAngles& measured,
                                             const JointVelocity& previous, double gain,
                                             double max_speed, double max_accel,
                                             double dt_s) noexcept;

/// @brief Largest |goal - measured| over the joints, in degrees. @pre none.
[[nodiscard]] double max_joint_error(const JointAngles& goal, const JointAngles& measured) noexcept;

}  // namespace orthoflow::drivers::jaco
