#pragma once
/// @file
/// @brief (internal) The body_filter node's settings, shared by the node (body_filter_node.cpp)
/// and the parsing of its parameters (body_filter_settings.cpp): the arm's link model and where
/// the camera is, the instructor zones, and how old an arm state may be.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "engine/params.hpp"
#include "kernels/capsule_mask.hpp"
#include "manipulation/arm_body.hpp"

namespace orthoflow::graphs {

/// @brief Instructor zones at most (thesis: C_instructor, a configured region where a person's
/// hands come in: nothing there is segmented, so nothing there is taught).
inline constexpr std::size_t MAX_ZONES = 8;
static_assert(manipulation::ARM_BODY_CAPSULES + MAX_ZONES <= kernels::MAX_CAPSULES);

/// @brief What one body_filter node does, fixed when it is built (parse_body_filter_settings).
/// Plain values.
struct BodyFilterSettings {
  bool arm = true;  ///< false: arm none, the zones only (no state needed, no frame dropped)
  std::array<kernels::Capsule, MAX_ZONES> zones{};
  std::size_t zone_count = 0;
  Eigen::Isometry3d base_from_camera = Eigen::Isometry3d::Identity();
  manipulation::ArmBodyModel model{};
  const drivers::jaco::ArmGeometry* geometry = &drivers::jaco::jaco2_geometry();
  std::int64_t max_state_age_ns = 50'000'000;
};

/// @brief The settings of a body_filter node from its parameters (robot_frames or
/// base_from_camera, max_state_age_ms, margin, arm, exclude; state and state_topic are the node
/// maker's). @pre none: every bad or contradicting parameter is an error naming it. Reads the
/// robot frames file when one is named.
[[nodiscard]] Result<BodyFilterSettings, std::string> parse_body_filter_settings(
    const engine::ParamMap& params);

}  // namespace orthoflow::graphs
