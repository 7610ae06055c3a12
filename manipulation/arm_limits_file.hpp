#pragma once
/// @file
/// @brief The arm's limits file (docs/SAFETY.md): one readable YAML file that says where the arm
/// may go. Every key is optional; what a file leaves out keeps the built-in default, and the
/// defaults are keep-outs, not free space: the table (everything below `table_height_m` in the
/// arm's base frame, the base column excepted), the arm's own base, and the camera with its mount
/// (placed where the robot frames put the camera, when a caller has them). A person removes one
/// only by saying so (`remove: [camera]`).
///
/// ```yaml
/// table_height_m: 0.0                       # the table's top in the base frame
/// workspace_m: [-0.9, -0.9, -0.1, 0.9, 0.9, 1.2]
/// keep_out:                                 # more boxes, base frame: [x0, y0, z0, x1, y1, z1]
///   - {name: shelf, box_m: [0.3, 0.3, 0.0, 0.6, 0.6, 0.4], from: upper_arm}
/// camera_half_extent_m: [0.15, 0.10, 0.10]  # around the camera's origin
/// camera_mount: true                        # and the column under it, down to the table
/// remove: []                                # default keep-outs a person takes away: table, base,
///                                           # camera
/// speed_deg_s: 30                           # host-commanded joint speed (hardware: 36 / 48)
/// accel_deg_s2: 40                          # host-commanded joint acceleration
/// brake_decel_deg_s2: 40                    # the braking the monitor assumes
/// command_latency_ms: 20
/// ```
/// Refused, with the key named: unknown or duplicate keys, values that are not finite numbers, an
/// inverted or empty box, anything that widens the hardware's documented ranges (speeds past the
/// JACO2's, joint limits past Kinova's, a workspace past the arm's reach), more keep-outs than
/// the driver holds. Not for the frame path (start-up only).
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "drivers/jaco/jaco_safety.hpp"

namespace orthoflow::manipulation {

/// @brief The arm's limits as a file (or the defaults) gave them.
struct ArmLimitsFile {
  drivers::jaco::SafetyLimits limits{};  ///< everything but the camera's box
  double table_height_m = 0.0;
  Eigen::Vector3d camera_half_extent_m{0.15, 0.10, 0.10};
  bool camera_mount = true;
  bool camera_removed = false;       ///< a person removed the camera's keep-out
  std::vector<std::string> removed;  ///< the default keep-outs a person took away
  std::string source = "built-in defaults";
};

/// @brief The built-in defaults (table at 0, the base's box, a camera box once placed). @pre none.
[[nodiscard]] ArmLimitsFile default_arm_limits();
/// @brief Parses a limits file's text. @return a sentence naming the key on error.
[[nodiscard]] Result<ArmLimitsFile, std::string> parse_arm_limits(std::string_view yaml,
                                                                  std::string source);
/// @brief Reads @p path (a regular file of at most 64 KiB) and parses it. @pre none.
[[nodiscard]] Result<ArmLimitsFile, std::string> load_arm_limits(const std::string& path);
/// @brief Places the camera's keep-out (and its mount) where @p base_from_camera puts the
/// camera, unless a person removed it. @return an error when the keep-outs are full.
[[nodiscard]] Result<void, std::string> place_camera_keep_out(
    ArmLimitsFile& file, const Eigen::Isometry3d& base_from_camera);
/// @brief The active limits as text a person reads (`orthoflow arm limits`). @note Allocates.
[[nodiscard]] std::string describe_limits(const ArmLimitsFile& file);

}  // namespace orthoflow::manipulation
