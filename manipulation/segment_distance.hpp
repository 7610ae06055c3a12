#pragma once
/// @file
/// @brief The distance from a point to a segment: the one geometric primitive the path checks
/// (execution_manager.hpp) and the occlusion test (arm_body.hpp) share. No allocation.
#include <algorithm>

#include <Eigen/Core>

namespace orthoflow::manipulation {

/// @brief Distance from @p p to the segment [@p a, @p b] (a point if a == b). @pre finite inputs.
[[nodiscard]] inline double distance_to_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                const Eigen::Vector3d& p) noexcept {
  const Eigen::Vector3d d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (p - a - t * d).norm();
}

}  // namespace orthoflow::manipulation
