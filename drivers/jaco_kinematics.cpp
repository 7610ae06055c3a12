#include "drivers/jaco_kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include "core/assert.hpp"

namespace orthoflow::drivers::jaco {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

constexpr double PI = std::numbers::pi;
constexpr double DEG = PI / 180.0;

Vector6d vec(const JointAngles& a) noexcept { return Eigen::Map<const Vector6d>(a.data()); }

// Levenberg-Marquardt settings. A radian at the tool weighs like the displacement it causes there.
constexpr double ORIENTATION_WEIGHT_M = 0.2;  // m: about the wrist-to-tool distance
constexpr int MAX_ITERATIONS = 64;
constexpr double LAMBDA_START = 1e-3;  // m^2: about 3 cm of damping on a 0.5 m lever
constexpr double LAMBDA_MIN = 1e-12;
constexpr double LAMBDA_MAX = 1e2;  // beyond this the step is nil: a local minimum or a limit
constexpr double MAX_STEP_RAD = 0.5;
constexpr double EARLY_ACCEPT_DEG = 60.0;

// Kinova's classical table of the 6-DOF curved-wrist arm (docs/JACO_KINEMATICS_SOURCES.md): the
// three wrist rows carry the lengths projected onto the 2aa-inclined wrist axes, sa / s2a.
ArmGeometry curved_wrist(double d4, double d5, double d6, double aa, double offset6) noexcept {
  constexpr double D1 = 0.2755, D2 = 0.4100, D3 = 0.2073, E2 = 0.0098;
  const double k = std::sin(aa) / std::sin(2.0 * aa);
  return {{{{D1, 0.0, PI / 2, -1.0, 0.0},  // {d, a, alpha, sign, offset}
            {0.0, D2, PI, 1.0, -PI / 2},
            {-E2, 0.0, PI / 2, 1.0, PI / 2},
            {-(D3 + k * d4), 0.0, 2.0 * aa, 1.0, 0.0},
            {-(k * d4 + k * d5), 0.0, 2.0 * aa, 1.0, -PI},
            {-(k * d5 + d6), 0.0, PI, 1.0, offset6}}}};
}

Eigen::Isometry3d dh_transform(const DhRow& row, double q_rad) noexcept {
  const double theta = row.sign * q_rad + row.offset_rad;
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(row.alpha_rad), sa = std::sin(row.alpha_rad);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() << ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca;
  t.translation() << row.a_m * ct, row.a_m * st, row.d_m;
  return t;
}

// The tip and, per joint, its axis and a point on it in the base frame (z axis and origin of the
// frame before the joint's row): forward kinematics and what the geometric Jacobian needs.
struct Chain {
  Eigen::Isometry3d tip = Eigen::Isometry3d::Identity();
  std::array<Eigen::Vector3d, 6> axis{}, origin{};
};

Chain chain(const ArmGeometry& g, const Vector6d& q_rad) noexcept {
  Chain c;
  for (std::size_t i = 0; i < 6; ++i) {
    c.axis[i] = c.tip.linear().col(2);
    c.origin[i] = c.tip.translation();
    c.tip = c.tip * dh_transform(g.rows[i], q_rad(static_cast<Eigen::Index>(i)));
  }
  return c;
}

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

Eigen::Isometry3d to_transform(const CartesianPose& pose) noexcept {
  Eigen::Isometry3d t(Eigen::AngleAxisd(pose.theta.x(), Eigen::Vector3d::UnitX()) *
                      Eigen::AngleAxisd(pose.theta.y(), Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(pose.theta.z(), Eigen::Vector3d::UnitZ()));
  t.translation() = pose.position;
  return t;
}

// R = Rx Ry Rz: theta x from column 2 (sy, -sx cy, cx cy), then y and z from Rx(-tx) R = Ry Rz, so
// that theta z absorbs any error of theta x: exact round trips near gimbal lock too.
CartesianPose to_pose(const Eigen::Isometry3d& transform) noexcept {
  const Eigen::Matrix3d& r = transform.linear();
  const double cy_sx = -r(1, 2), cy_cx = r(2, 2);
  const double tx = std::hypot(cy_sx, cy_cx) < 1e-15 ? 0.0 : std::atan2(cy_sx, cy_cx);
  const double cx = std::cos(tx), sx = std::sin(tx);
  const double sz = cx * r(1, 0) + sx * r(2, 0), cz = cx * r(1, 1) + sx * r(2, 1);
  const double cy = std::max(0.0, -sx * r(1, 2) + cx * r(2, 2));  // >= 0 but for rounding
  return {transform.translation(), {tx, std::atan2(r(0, 2), cy), std::atan2(sz, cz)}};
}

const ArmGeometry& jaco2_geometry() noexcept {
  static const ArmGeometry g = curved_wrist(0.0741, 0.0741, 0.1600, PI / 6, PI / 2);
  return g;
}

const ArmGeometry& jaco_v1_geometry() noexcept {
  static const ArmGeometry g = curved_wrist(0.0743, 0.0743, 0.1687, 11 * PI / 72, 100 * DEG);
  return g;
}

bool JointLimits::contains(const JointAngles& angles) const noexcept {
  const Eigen::Array<double, 6, 1> q = vec(angles);  // compared so that NaN is outside
  return ((q >= vec(lower).array()) && (q <= vec(upper).array())).all();
}

JointLimits jaco_joint_limits() noexcept {
  constexpr double C = CONTINUOUS_BOUND_DEG;
  return {{-C, 47.0, 19.0, -C, -C, -C}, {C, 313.0, 341.0, C, C, C}};
}

Eigen::Isometry3d forward_kinematics(const JointAngles& actuator_deg) noexcept {
  return forward_kinematics(actuator_deg, jaco2_geometry());
}

Eigen::Isometry3d forward_kinematics(const JointAngles& actuator_deg,
                                     const ArmGeometry& geometry) noexcept {
  return chain(geometry, vec(actuator_deg) * DEG).tip;
}

ChainFrames forward_kinematics_frames(const JointAngles& actuator_deg,
                                      const ArmGeometry& geometry) noexcept {
  ChainFrames frames;
  frames[0] = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < 6; ++i) {
    frames[i + 1] = frames[i] * dh_transform(geometry.rows[i], actuator_deg[i] * DEG);
  }
  return frames;
}

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
