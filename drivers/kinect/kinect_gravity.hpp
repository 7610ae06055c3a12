#pragma once
/// @file
/// @brief "Up" in the depth camera's frame from the Kinect's accelerometer (the motor state's raw
/// counts, specs/KINECT_V1.md 11; fakenect's `a-*.dump` records hold the same counts).
///
/// Axes: the camera frame is x right, y down, z forward (the depth pixels' pinhole). At rest the
/// accelerometer reads the reaction to gravity, +1 g along "up"; a level Kinect reads about
/// (0, +819, 0) and one pitched up by `a` degrees about (0, 819 cos a, 819 sin a), the pitch
/// sign the motor reports (tilt angle). So the accelerometer's y points up and its z forward, and,
/// for a right-handed frame, its x points left: up in the camera frame is (-x, -y, z) normalised.
/// KINECT_V1.md does not state the x axis; a roll of the head is the only motion it affects, and
/// the simulated motor (simulation/devices) models no roll.
#include <array>
#include <cstdint>
#include <optional>

namespace orthoflow::drivers::kinect {

/// @brief A reading is used only if its magnitude is within this of 1 g (819 counts): a Kinect
/// being moved or a corrupt reading (all zero, saturated) says nothing about where up is.
inline constexpr double GRAVITY_TOLERANCE_G = 0.3;

/// @brief Unit "up" in the depth camera frame from raw accelerometer counts, or nullopt when the
/// reading is not a plausible gravity (magnitude outside 1 g +- GRAVITY_TOLERANCE_G). @note Pure.
[[nodiscard]] std::optional<std::array<float, 3>> up_from_accel(std::int16_t x, std::int16_t y,
                                                                std::int16_t z) noexcept;

}  // namespace orthoflow::drivers::kinect
