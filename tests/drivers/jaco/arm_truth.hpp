#pragma once
// What the simulated arm really did, judged by its ground truth (the simulator's joints and
// fingers), not by what the driver believed: the true body (capsules without the monitor's
// margin) and how deep it reaches into a keep-out or out of the workspace.
#include <algorithm>
#include <cmath>
#include <limits>

#include "drivers/jaco/jaco_clearance.hpp"
#include "simulation/devices/sim_jaco_arm.hpp"

namespace orthoflow::test {

/// The true body's worst clearance (m; negative: that deep inside a keep-out or outside the
/// workspace) at the simulator's joints and fingers, holding @p held.
inline drivers::jaco::BodyClearance true_clearance(const drivers::jaco::SafetyLimits& limits,
                                                   const simulation::SimJacoArm& arm,
                                                   const drivers::jaco::HeldCapsule& held = {}) {
  namespace jaco = drivers::jaco;
  jaco::BodyModel exact = limits.body;
  exact.margin_m = 0.0;
  double widest = limits.max_finger;
  for (double f : arm.fingers()) widest = std::min(widest, f);
  const double open = std::clamp(1.0 - widest / limits.max_finger, 0.0, 1.0);
  jaco::BodyCapsules body{};
  const std::size_t n =
      jaco::body_capsules(arm.joints(), *limits.geometry, exact, open, held, body);
  std::array<double, jaco::MAX_BODY_CAPSULES> none{};
  return jaco::body_clearance(limits, std::span(body.data(), n), none);
}

}  // namespace orthoflow::test
