#include "drivers/jaco/jaco_motion.hpp"

#include <algorithm>
#include <cmath>

namespace orthoflow::drivers::jaco {

// The path is start + s(t) * (goal - start) with s a trapezoid in time from 0 to 1. The joint with
// the longest travel D sets the caps: s' <= max_speed / D, s'' <= max_accel / D.
JointProfile::JointProfile(const JointAngles& start, const JointAngles& goal, double max_speed,
                           double max_accel) noexcept
    : start_(start), goal_(goal) {
  double travel = 0.0;
  for (std::size_t j = 0; j < JOINTS; ++j) travel = std::max(travel, std::abs(goal[j] - start[j]));
  if (travel < 1e-9) return;
  const double v = max_speed / travel;  // normalised speed cap
  const double a = max_accel / travel;  // normalised acceleration cap
  if (v * v / a >= 1.0) {               // triangle: the cap speed is never reached
    accel_time_ = std::sqrt(1.0 / a);
    peak_ = a * accel_time_;
    duration_ = 2.0 * accel_time_;
  } else {
    accel_time_ = v / a;
    peak_ = v;
    duration_ = accel_time_ + 1.0 / v;
  }
}

namespace {
// Normalised progress s(t) and its rate for a trapezoid of ramp time ta, peak p and length T.
void progress(double t, double ta, double p, double T, double& s, double& ds) noexcept {
  if (T <= 0.0 || t >= T) {
    s = 1.0;
    ds = 0.0;
    return;
  }
  if (t <= 0.0) {
    s = 0.0;
    ds = 0.0;
    return;
  }
  const double a = p / ta;
  if (t < ta) {
    s = 0.5 * a * t * t;
    ds = a * t;
  } else if (t <= T - ta) {
    s = 0.5 * a * ta * ta + p * (t - ta);
    ds = p;
  } else {
    const double r = T - t;
    s = 1.0 - 0.5 * a * r * r;
    ds = a * r;
  }
}
}  // namespace

JointAngles JointProfile::position(double t_s) const noexcept {
  double s = 1.0, ds = 0.0;
  progress(t_s, accel_time_, peak_, duration_, s, ds);
  JointAngles q{};
  for (std::size_t j = 0; j < JOINTS; ++j) q[j] = start_[j] + s * (goal_[j] - start_[j]);
  return q;
}

JointVelocity JointProfile::velocity(double t_s) const noexcept {
  double s = 1.0, ds = 0.0;
  progress(t_s, accel_time_, peak_, duration_, s, ds);
  JointVelocity v{};
  for (std::size_t j = 0; j < JOINTS; ++j) v[j] = ds * (goal_[j] - start_[j]);
  return v;
}

JointVelocity velocity_command(const JointProfile& profile, double t_s, const JointAngles& measured,
                               const JointVelocity& previous, double gain, double max_speed,
                               double max_accel, double dt_s) noexcept {
  const JointAngles planned = profile.position(t_s);
  const JointVelocity feed = profile.velocity(t_s);
  JointVelocity out{};
  const double step = max_accel * dt_s;
  for (std::size_t j = 0; j < JOINTS; ++j) {
    double v = feed[j] + gain * (planned[j] - measured[j]);
    v = std::clamp(v, -max_speed, max_speed);
    v = std::clamp(v, previous[j] - step, previous[j] + step);
    out[j] = v;
  }
  return out;
}

double max_joint_error(const JointAngles& goal, const JointAngles& measured) noexcept {
  double e = 0.0;
  for (std::size_t j = 0; j < JOINTS; ++j) e = std::max(e, std::abs(goal[j] - measured[j]));
  return e;
}

}  // namespace orthoflow::drivers::jaco
