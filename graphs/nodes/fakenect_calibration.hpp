#pragma once
/// @file
/// @brief fakenect's `device.json` (specs/USB_TESTING.md 2.3) from and to the Kinect driver's
/// calibration (drivers/kinect/kinect_protocol.hpp), so `orthoflow kinect record` writes what
/// libfreenect's replay reads and `replay_source` converts recorded depth with the recorded
/// device's parameters. Layout: {"reg_info": {24 registration words by name, "pad_info": {...},
/// "zero_plane_info":
/// {...}}, "const_shift": n}. Words are matched by name; the 5 fakenect drops (dx_center,
/// rollout_blank, rollout_size, back_comp1, back_comp2) read back as 0.
#include <array>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/result.hpp"
#include "drivers/kinect/kinect_protocol.hpp"
#include "formats/io_error.hpp"

namespace orthoflow::graphs {

/// @brief device.json's text for @p calibration.
[[nodiscard]] std::string fakenect_device_json(const drivers::kinect::Calibration& calibration);
/// @brief Writes device.json (atomically).
[[nodiscard]] Result<void, formats::IoError> write_fakenect_device(
    const std::filesystem::path& path, const drivers::kinect::Calibration& calibration);
/// @brief Parses device.json text; every key must be present and a finite number in range (the
/// ranges of drivers::kinect::parse_fixed_params), else an error naming the key. Fuzzed.
[[nodiscard]] Result<drivers::kinect::Calibration, formats::IoError> parse_fakenect_device(
    std::string_view text, const std::string& name);
/// @brief Reads and parses device.json.
[[nodiscard]] Result<drivers::kinect::Calibration, formats::IoError> read_fakenect_device(
    const std::filesystem::path& path);

}  // namespace orthoflow::graphs
