// The monitor's geometry: capsules against boxes (jaco_clearance.hpp).
#include "drivers/jaco/jaco_clearance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace orthoflow::drivers::jaco {
namespace {

// Golden-section steps: the bracket shrinks to 0.618^60 (< 1e-12) of the segment.
constexpr int GOLDEN_STEPS = 60;
constexpr double INV_PHI = 0.6180339887498949;

double point_box_distance(const Eigen::Vector3d& p, const Box& box) noexcept {
  const Eigen::Vector3d outside =
      (box.min - p).cwiseMax(Eigen::Vector3d::Zero()).cwiseMax(p - box.max);
  return outside.norm();
}

}  // namespace

double segment_box_distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Box& box,
                            double enough, Eigen::Vector3d& nearest) noexcept {
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  const Eigen::Vector3d middle = a + 0.5 * d;
  const double cheap = point_box_distance(middle, box) - 0.5 * length;
  nearest = middle;
  if (cheap >= enough) return cheap;
  // The distance from a point moving along the segment to a convex box is a convex function of
  // the parameter: golden-section search finds its minimum, and since the point moves by `length`
  // per unit of parameter, the value at the best point less length x the final bracket is a lower
  // bound of the true minimum.
  double lo = 0.0, hi = 1.0;
  double x1 = hi - INV_PHI * (hi - lo), x2 = lo + INV_PHI * (hi - lo);
  double f1 = point_box_distance(a + x1 * d, box), f2 = point_box_distance(a + x2 * d, box);
  double best = std::min({point_box_distance(a, box), point_box_distance(b, box), f1, f2});
  for (int i = 0; i < GOLDEN_STEPS && best > 0.0; ++i) {
    if (f1 <= f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - INV_PHI * (hi - lo);
      f1 = point_box_distance(a + x1 * d, box);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + INV_PHI * (hi - lo);
      f2 = point_box_distance(a + x2 * d, box);
    }
    best = std::min({best, f1, f2});
  }
  nearest = a + (f1 <= f2 ? x1 : x2) * d;
  return std::max(0.0, best - length * (hi - lo));
}

double capsule_inside_margin(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                             const Box& box, Eigen::Vector3d& worst) noexcept {
  // A box is convex: the capsule lies inside it exactly when both ends lie inside it shrunk by the
  // radius, so the margin is the smaller of the ends' distances to the walls, less the radius.
  const auto margin = [&](const Eigen::Vector3d& p) {
    return std::min((p - box.min).minCoeff(), (box.max - p).minCoeff()) - radius;
  };
  const double ma = margin(a), mb = margin(b);
  worst = ma <= mb ? a : b;
  return std::min(ma, mb);
}

BodyClearance body_clearance(const SafetyLimits& limits, std::span<const BodyCapsule> body,
                             std::span<const double> inflation) noexcept {
  BodyClearance worst;
  worst.margin_m = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < body.size(); ++c) {
    const BodyCapsule& capsule = body[c];
    if (capsule.part == BodyPart::BASE) continue;  // it never moves in space (jaco_body.hpp)
    const double grow = inflation[c];
    Eigen::Vector3d point;
    const double inside = capsule_inside_margin(capsule.a, capsule.b, capsule.radius_m + grow,
                                                limits.workspace, point);
    if (inside < worst.margin_m) worst = {inside, c, &limits.workspace, true, point};
    for (std::size_t k = 0; k < limits.keep_out_count; ++k) {
      const Box& box = limits.keep_out[k];
      if (capsule.part < box.from) continue;
      const double needed = capsule.radius_m + grow;
      const double distance =
          segment_box_distance(capsule.a, capsule.b, box, needed + 0.05, point) - needed;
      if (distance < worst.margin_m) worst = {distance, c, &box, false, point};
    }
  }
  return worst;
}

}  // namespace orthoflow::drivers::jaco
