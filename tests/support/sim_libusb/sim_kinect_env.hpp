#pragma once
/// @file
/// @brief The simulated bus of the libusb-1.0 shim (sim_libusb.cpp), read from the environment,
/// and shared with the tests that check what a libusb program received from it (they build the
/// same SimKinectDevice from the same string).
///
/// ORTHOFLOW_SIM_KINECT: unset or empty = one default Kinect (model 1414, the SimKinectConfig
/// defaults); "none" = no Kinect (the bus then holds only the ORTHOFLOW_SIM_JACO arms of
/// sim_jaco_env.hpp, if any). Otherwise Kinects separated by ';', each a ','-separated list of
/// key=value (whitespace around tokens is ignored; an empty entry between ';' is a default Kinect):
///   model=1414|1473|k4w   serial=<16 chars>   seed=<u64 scene seed>   bus=<1..255>
///   ports=<p>[.<p>...]    (the internal hub's port path from the root hub, 1..6 ports of 1..15)
///   audio=0|1             (list the audio function)
///   depth=scene|ramp      (scene: the seeded tabletop, the same image every frame; ramp: raw =
///                          300 + (x + 2 y + 13 frame) mod 1500, a different image per frame)
///   drop=|duplicate=|corrupt=|reorder=<rate in [0, 1]>   fault_seed=<u64>
/// Kinect k (from 0) defaults to serial "A00364A11700045A" for k = 0 and "A00364A11700045" +
/// hex digit k otherwise, and to ports=<k + 1>, so several Kinects differ without being told.
/// Anything else (unknown key, bad number, duplicate serial or hub) is an error.
///
/// ORTHOFLOW_SIM_KINECT_PACE: unset, empty or "realtime" = simulated time never runs ahead of the
/// wall clock (30 frames per real second); "max" = as fast as the program pumps events.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/result.hpp"
#include "simulation/devices/sim_kinect_device.hpp"

namespace orthoflow::sim_libusb {

inline constexpr const char* ENV_KINECT = "ORTHOFLOW_SIM_KINECT";
inline constexpr const char* ENV_PACE = "ORTHOFLOW_SIM_KINECT_PACE";
inline constexpr const char* ENV_TRACE = "ORTHOFLOW_SIM_KINECT_TRACE";

/// @brief The ramp depth image of frame @p frame (see depth=ramp). @pre raw.size() == 640 * 480.
void ramp_depth(std::uint64_t frame, std::span<std::uint16_t> raw) noexcept;

/// @brief The Kinects @p text describes (syntax above). @return a message naming the bad token.
/// @note Allocates; no exceptions escape.
[[nodiscard]] Result<std::vector<simulation::SimKinectConfig>, std::string> parse_kinects(
    std::string_view text);

/// @brief Pacing from ORTHOFLOW_SIM_KINECT_PACE's value. @return false = max, true = realtime.
[[nodiscard]] Result<bool, std::string> parse_pace(std::string_view text);

/// @brief parse_kinects of getenv(ENV_KINECT) (unset = empty).
[[nodiscard]] Result<std::vector<simulation::SimKinectConfig>, std::string> kinects_from_env();

}  // namespace orthoflow::sim_libusb
