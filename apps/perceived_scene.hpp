#pragma once
/// @file
/// @brief What `orthoflow grasp` and `orthoflow task` read: one frame of `orthoflow run --json-out`
/// (the one --frame names, else the last with objects) and the table plane carried into the arm's
/// base frame through the robot frames file. Failures go out as CLI errors naming the file.
#include <cstdint>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>

#include "manipulation/grasp_planner.hpp"
#include "manipulation/robot_frames.hpp"

namespace orthoflow::apps {

struct PerceivedScene {
  Eigen::Isometry3d base_from_camera = Eigen::Isometry3d::Identity();
  manipulation::PerceivedFrame frame;
  manipulation::SupportPlane table;  ///< base frame, normal up (toward the camera's side)
};

/// @brief Loads the robot frames and the chosen frame; throws CLI::RuntimeError(EXIT_BAD_INPUT)
/// with "orthoflow @p command: ..." on stderr.
/// @brief The check of a coordinate option on the table (base frame): a finite number in [-2, 2] m.
/// Signed, so such options also carry a type name of their own (apps/option_checks.hpp).
[[nodiscard]] CLI::Validator table_coordinate();

[[nodiscard]] PerceivedScene load_perceived_scene(const std::string& command,
                                                  const std::string& frames_file,
                                                  const std::string& objects_file,
                                                  std::optional<std::uint64_t> frame);

}  // namespace orthoflow::apps
