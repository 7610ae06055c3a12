#pragma once
/// @file
/// @brief The geometry under the safety monitor (jaco_safety_monitor.hpp): how far the arm's body
/// (jaco_body.hpp) stays from every keep-out box and inside the workspace box, as one clearance in
/// metres for the worst capsule, with the part and the box it concerns. Distances are lower bounds
/// (never larger than the true distance), so a positive clearance is a proof. Pure; no allocation;
/// deterministic.
#include <cstddef>
#include <span>

#include <Eigen/Core>

#include "drivers/jaco/jaco_body.hpp"
#include "drivers/jaco/jaco_safety.hpp"

namespace orthoflow::drivers::jaco {

/// @brief A lower bound of the distance between the segment [@p a, @p b] and @p box (0 when they
/// meet), at most 1e-9 m below the true distance. @p nearest gets the segment's point found
/// nearest. @pre finite points.
/// Pairs whose cheap bound (the box's distance from the segment's middle, less half its length)
/// already reaches @p enough are not refined: the bound is returned as it is.
[[nodiscard]] double segment_box_distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Box& box, double enough,
                                          Eigen::Vector3d& nearest) noexcept;

/// @brief How far the capsule [@p a, @p b] of radius @p radius stays inside @p box: the smallest
/// distance from its surface to a wall (negative: it reaches that far outside). Exact for a box.
/// @p worst gets the endpoint that comes nearest a wall. @pre finite values.
[[nodiscard]] double capsule_inside_margin(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                           double radius, const Box& box,
                                           Eigen::Vector3d& worst) noexcept;

/// @brief The worst margin of a body, and where.
struct BodyClearance {
  double margin_m = 0.0;     ///< smallest (clearance - inflation) over the walls and keep-outs
  std::size_t capsule = 0;   ///< index of the capsule it concerns
  const Box* box = nullptr;  ///< the keep-out, or the workspace
  bool workspace = false;    ///< true: the workspace's wall, false: a keep-out
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

/// @brief The margin of @p body, each capsule c inflated by @p inflation[c], against the workspace
/// and every keep-out of @p limits that applies to its part (Box::from): the smallest clearance
/// less inflation, a lower bound. The base column is left out (it never moves in space).
/// @pre body not empty; inflation.size() >= body.size().
[[nodiscard]] BodyClearance body_clearance(const SafetyLimits& limits,
                                           std::span<const BodyCapsule> body,
                                           std::span<const double> inflation) noexcept;

}  // namespace orthoflow::drivers::jaco
