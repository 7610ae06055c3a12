#pragma once
/// @file
/// @brief (internal) The calibration target in depth frames (apps/cmd_calibrate_target.cpp):
/// `calibrate find-target` turns frames of the ball in the gripper, with the arm's joints at each,
/// into a samples file for `calibrate hand-eye`; `calibrate simulate-frames` renders such frames
/// from a simulated rig with a known camera.
#include <CLI/CLI.hpp>

namespace orthoflow::apps {

/// @brief find-target and simulate-frames under the calibrate command.
void add_calibrate_target_commands(CLI::App* calibrate);

}  // namespace orthoflow::apps
