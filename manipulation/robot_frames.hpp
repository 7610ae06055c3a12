#pragma once
/// @file
/// @brief The robot's frames as configuration: the camera's pose in the arm's base frame (what
/// `orthoflow calibrate hand-eye` writes and `orthoflow grasp` reads), and the calibration
/// samples file. Two small text formats, both parsed with a clear error for anything malformed
/// (fuzzed: tests/fuzz/fuzz_robot_frames.cpp):
///
/// Robot frames (YAML):
///
///     base_from_camera:
///       translation_m: [0.25, -1.0, 0.7]
///       rotation_wxyz: [w, x, y, z]     # unit quaternion (normalised if within 1e-3 of unit)
///
/// Calibration samples (JSON lines, one sample per line, blank lines and lines starting with '#'
/// skipped). The arm side is either the joint reading or the Cartesian reading, the camera side
/// either the target's pose or its centre:
///
///     {"joints": [q1, ..., q6]  |  "gripper": {"position": [x,y,z], "theta": [tx,ty,tz]},
///      "target": {"position": [x,y,z], "theta": [tx,ty,tz]}  |  "target_point": [x,y,z]}
///
/// joints in actuator degrees (forward kinematics of the chosen model); positions in metres;
/// theta in radians, R = Rx * Ry * Rz (the arm's Cartesian convention,
/// drivers/jaco/jaco_kinematics.hpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "drivers/jaco/jaco_kinematics.hpp"
#include "manipulation/hand_eye.hpp"

namespace orthoflow::manipulation {

/// @brief The configured frames.
struct RobotFrames {
  Eigen::Isometry3d base_from_camera = Eigen::Isometry3d::Identity();
};

/// @brief Parses robot frames from YAML text; the error names the key and what is wrong.
[[nodiscard]] Result<RobotFrames, std::string> parse_robot_frames(std::string_view yaml);
/// @brief Reads and parses a robot frames file; the error names the file.
[[nodiscard]] Result<RobotFrames, std::string> load_robot_frames(const std::string& path);
/// @brief The YAML text of @p frames (round-trips through parse_robot_frames to 1e-12), with an
/// optional comment block (each line prefixed with '# ').
[[nodiscard]] std::string format_robot_frames(const RobotFrames& frames,
                                              std::string_view comment = {});

/// @brief One parsed line of a samples file.
struct CalibrationLine {
  std::variant<PoseSample, PointSample> sample;
};
/// @brief Parses one samples line with forward kinematics on @p geometry; nullopt for a blank or
/// comment line; the error says what is wrong. @pre none.
[[nodiscard]] Result<std::optional<CalibrationLine>, std::string> parse_calibration_line(
    std::string_view line, const drivers::jaco::ArmGeometry& geometry);

/// @brief One line of a poses file of `orthoflow calibrate find-target`: a depth frame of the
/// calibration ball and the arm's joints when it was taken.
struct TargetFrameLine {
  std::string frame;                    ///< the frame's PCD file, as written in the line
  drivers::jaco::JointAngles joints{};  ///< actuator degrees
};
/// @brief Parses one poses line ({"frame": "FILE.pcd", "joints": [6 numbers]}); nullopt for a
/// blank or comment line; the error says what is wrong. @pre none.
[[nodiscard]] Result<std::optional<TargetFrameLine>, std::string> parse_target_frame_line(
    std::string_view line);

/// @brief One object of a line of `orthoflow run --json-out` (the fields the planner uses).
struct PerceivedObject {
  std::uint64_t track = 0;
  std::string label;  ///< empty when Unknown
  std::string truth;  ///< the synthetic ground truth's category, when the source knows it
  std::array<float, 16> frame{};  ///< GOOD's world -> object, row-major
  std::array<float, 3> bbox{};
  bool described = false;  ///< false when the line has no frame for it
};
/// @brief One frame of `orthoflow run --json-out`.
struct PerceivedFrame {
  std::uint64_t frame = 0;
  bool has_plane = false;
  Eigen::Vector3d plane_normal = Eigen::Vector3d::Zero();  ///< sensor frame: n . p + d = 0
  double plane_d = 0.0;
  std::vector<PerceivedObject> objects;
};
/// @brief Parses one line of `orthoflow run --json-out`; the error says what is wrong. @pre none.
[[nodiscard]] Result<PerceivedFrame, std::string> parse_run_line(std::string_view line);

}  // namespace orthoflow::manipulation
