// Inverse kinematics of the JACO (jaco_kinematics.hpp): damped least squares (Levenberg-Marquardt)
// on the pose error with joint limits held by an active set, from the seed and then a fixed
// sequence of restarts; the solution nearest the seed wins. The chain is in jaco_chain.hpp.
#include "drivers/jaco/jaco_kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/assert.hpp"
#include "drivers/jaco/jaco_chain.hpp"

namespace orthoflow::drivers::jaco {
namespace {

using detail::Chain;
using detail::chain;
using detail::DEG;
using detail::vec;
using detail::Vector6d;

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Levenberg-Marquardt settings. A radian at the tool weighs like the displacement it causes there.
constexpr double ORIENTATION_WEIGHT_M = 0.2;  // m: about the wrist-to-tool distance
constexpr int MAX_ITERATIONS = 64;
constexpr double LAMBDA_START = 1e-3;  // m^2: about 3 cm of damping on a 0.5 m lever
constexpr double LAMBDA_MIN = 1e-12;
constexpr double LAMBDA_MAX = 1e2;  // beyond this the step is nil: a local minimum or a limit
constexpr double MAX_STEP_RAD = 0.5;
constexpr double EARLY_ACCEPT_DEG = 60.0;

// [position; rotation vector of R_target R^T (log map, base frame)]: exact for large errors.
Vector6d pose_error(const Eigen::Isometry3d& target, const Eigen::Isometry3d& current) noexcept {
  const Eigen::AngleAxisd delta(target.linear() * current.linear().transpose());
  Vector6d e;
  e << target.translation() - current.translation(), delta.angle() * delta.axis();
  return e;
}

bool within(const Vector6d& e, const IkTolerance& tol) noexcept {
  return e.head<3>().norm() <= tol.position_m && e.tail<3>().norm() <= tol.orientation_rad;
}
Vector6d weighted(Vector6d e) noexcept {  // the least-squares residual: both halves in metres
  e.tail<3>() *= ORIENTATION_WEIGHT_M;
  return e;
}

// d(pose)/d(actuator radian): z x (p - o) and z per revolute joint, times the row's sign.
Matrix6d jacobian(const ArmGeometry& g, const Chain& c) noexcept {
  Matrix6d j;
  const Eigen::Vector3d p = c.tip.translation();
  for (std::size_t i = 0; i < 6; ++i) {
    const auto col = static_cast<Eigen::Index>(i);
    j.block<3, 1>(0, col) = g.rows[i].sign * c.axis[i].cross(p - c.origin[i]);
    j.block<3, 1>(3, col) = g.rows[i].sign * ORIENTATION_WEIGHT_M * c.axis[i];
  }
  return j;
}

struct RadLimits {
  Vector6d lower, upper;
};
Vector6d clamp(const Vector6d& q, const RadLimits& lim) noexcept {
  return q.cwiseMax(lim.lower).cwiseMin(lim.upper);
}

// A damped least-squares step (largest joint step bounded) with an active set: a joint pushed past
// a limit is held at it and the others solved again (clamping the step bends it and stalls there).
Vector6d limited_step(const Matrix6d& j, const Vector6d& r, double lambda, const Vector6d& q,
                      const RadLimits& lim) noexcept {
  Vector6d held = Vector6d::Zero();  // 1 where a joint is held at a limit
  Vector6d step = Vector6d::Zero();
  for (int pass = 0; pass < 3; ++pass) {
    const Vector6d keep = Vector6d::Ones() - held;
    const Matrix6d jf = j * keep.asDiagonal();  // held joints' columns zeroed: they stay put
    Matrix6d a = jf.transpose() * jf;
    a.diagonal().array() += lambda;
    Vector6d free = a.llt().solve(jf.transpose() * (r - j * step.cwiseProduct(held)));
    const double largest = free.cwiseAbs().maxCoeff();
    if (largest > MAX_STEP_RAD) free *= MAX_STEP_RAD / largest;
    step = step.cwiseProduct(held) + free.cwiseProduct(keep);
    const Vector6d to_limit = clamp(q + step, lim) - q;
    const Vector6d hit = (to_limit.array() != step.array()).cast<double>();
    if (hit.isZero()) break;
    held = held.cwiseMax(hit);
    step = to_limit;
  }
  return step;
}

// Levenberg-Marquardt from @p q (updated); true at tolerance. A step that raises the cost is
// refused.
bool descend(const ArmGeometry& g, const Eigen::Isometry3d& target, const RadLimits& lim,
             const IkTolerance& tol, Vector6d& q) noexcept {
  Chain c = chain(g, q);
  Vector6d e = pose_error(target, c.tip);
  double lambda = LAMBDA_START;
  for (int it = 0; it < MAX_ITERATIONS; ++it) {
    if (within(e, tol)) return true;
    const Vector6d q_try =
        clamp(q + limited_step(jacobian(g, c), weighted(e), lambda, q, lim), lim);
    const Chain c_try = chain(g, q_try);
    const Vector6d e_try = pose_error(target, c_try.tip);
    if (weighted(e_try).squaredNorm() < weighted(e).squaredNorm()) {
      q = q_try;
      c = c_try;
      e = e_try;
      lambda = std::max(lambda * 0.1, LAMBDA_MIN);
    } else if ((lambda *= 10.0) > LAMBDA_MAX) {
      return false;
    }
  }
  return within(e, tol);
}

bool continuous(const JointLimits& limits, std::size_t i) noexcept {
  return limits.upper[i] - limits.lower[i] >= 360.0;
}

// Radian bounds; continuous joints go free (a clamp would block answers just past their bound).
RadLimits descent_limits(const JointLimits& limits) noexcept {
  const Eigen::Array<bool, 6, 1> free = (vec(limits.upper) - vec(limits.lower)).array() >= 360.0;
  return {free.select(-HUGE_VAL, vec(limits.lower).array() * DEG).matrix(),
          free.select(HUGE_VAL, vec(limits.upper).array() * DEG).matrix()};
}

// Continuous joints turned nearest the seed, then inside their bounds; all clamped (radians: ulps).
JointAngles wrap_near(const Vector6d& q_rad, const JointAngles& seed, const JointLimits& limits) {
  JointAngles out{};
  for (std::size_t i = 0; i < 6; ++i) {
    double v = q_rad(static_cast<Eigen::Index>(i)) / DEG;
    if (continuous(limits, i)) {
      v += 360.0 * std::round((seed[i] - v) / 360.0);
      v -= 360.0 * std::max(0.0, std::ceil((v - limits.upper[i]) / 360.0));
      v += 360.0 * std::max(0.0, std::ceil((limits.lower[i] - v) / 360.0));
    }
    out[i] = std::clamp(v, limits.lower[i], limits.upper[i]);
  }
  return out;
}

// The fixed restarts, degrees: first near the seed, wrist turned and joints 2, 3 toward mid-range
// (a descent ending on a limit beside a near-singular wrist, q5 near 0 or 180, needs both); then
// the branches (base half a turn, elbow up/down, wrist flip), absolute on joints 2, 3 only.
constexpr std::size_t NEAR_RESTARTS = 4;
// clang-format off
constexpr std::array<JointAngles, 12> RESTARTS = {{
    {0, 15, 15, 0, 30, 0},    {0, 15, 15, 0, -30, 0},    {0, 40, 40, 45, 60, -45},
    {0, 40, 40, -45, -60, 45}, {0, 180, 90, 0, 0, 0},     {0, 180, 270, 0, 0, 0},
    {180, 180, 90, 0, 0, 0},   {180, 180, 270, 0, 0, 0},  {0, 120, 60, 180, 0, 0},
    {0, 240, 300, 180, 0, 0},  {180, 120, 60, 180, 0, 0}, {180, 240, 300, 180, 0, 0}}};
// clang-format on

Vector6d restart(std::size_t k, const JointAngles& seed, const JointLimits& limits) noexcept {
  Vector6d q = vec(seed) + vec(RESTARTS[k]);
  for (std::size_t i = 0; i < 6; ++i) {
    if (continuous(limits, i)) continue;
    const double middle_side = limits.lower[i] + limits.upper[i] - 2.0 * seed[i];
    q(static_cast<Eigen::Index>(i)) =
        k < NEAR_RESTARTS ? seed[i] + std::copysign(RESTARTS[k][i], middle_side) : RESTARTS[k][i];
  }
  return q * DEG;
}

// No angles put the tip further from joint 2's circle centre than the sum of the other lengths.
bool beyond_reach(const ArmGeometry& g, const Eigen::Vector3d& p) noexcept {
  double reach = std::abs(g.rows[0].a_m);
  for (std::size_t i = 1; i < 6; ++i) reach += std::abs(g.rows[i].a_m) + std::abs(g.rows[i].d_m);
  return (p - Eigen::Vector3d(0.0, 0.0, g.rows[0].d_m)).norm() > reach;
}

}  // namespace

const char* to_string(IkError error) noexcept {
  switch (error) {
    case IkError::NOT_FINITE:
      return "not_finite";
    case IkError::UNREACHABLE:
      return "unreachable";
  }
  return "unknown";
}

Result<JointAngles, IkError> inverse_kinematics(const Eigen::Isometry3d& target,
                                                const JointAngles& seed, const JointLimits& limits,
                                                IkTolerance tolerance) noexcept {
  return inverse_kinematics(target, seed, limits, tolerance, jaco2_geometry());
}

Result<JointAngles, IkError> inverse_kinematics(const Eigen::Isometry3d& target,
                                                const JointAngles& seed, const JointLimits& limits,
                                                IkTolerance tolerance,
                                                const ArmGeometry& geometry) noexcept {
  OF_ASSERT(tolerance.position_m > 0.0 && tolerance.orientation_rad > 0.0, "tolerance <= 0");
  if (!target.matrix().allFinite() || !vec(seed).allFinite()) return err(IkError::NOT_FINITE);
  if (beyond_reach(geometry, target.translation())) return err(IkError::UNREACHABLE);
  OF_ASSERT((vec(limits.lower).array() <= vec(limits.upper).array()).all(), "limits inverted");
  const RadLimits lim = descent_limits(limits);
  JointAngles best{};
  double best_distance = HUGE_VAL;
  for (std::size_t k = 0; k <= RESTARTS.size(); ++k) {
    Vector6d q = clamp(k == 0 ? Vector6d(vec(seed) * DEG) : restart(k - 1, seed, limits), lim);
    if (!descend(geometry, target, lim, tolerance, q)) continue;
    const JointAngles solution = wrap_near(q, seed, limits);
    const double distance = (vec(solution) - vec(seed)).norm();
    if (distance < best_distance) std::tie(best, best_distance) = std::tie(solution, distance);
    if (k == 0 && distance <= EARLY_ACCEPT_DEG) break;
  }
  if (!std::isfinite(best_distance)) return err(IkError::UNREACHABLE);
  return best;
}

}  // namespace orthoflow::drivers::jaco
