#pragma once
/// @file
/// @brief A fast PNG for the camera view: 8-bit RGB through libpng at zlib level 1 with the SUB
/// filter. cairo's own PNG writer uses zlib's default level, which took 35-55 ms for a 320 x 240
/// colour Kinect image on the robot's cores (bench/RESULTS.md, "web view"); this is several times
/// cheaper for about a quarter more bytes.
#include <cstdint>
#include <string>

namespace orthoflow::ui {

/// @brief The PNG of @p height rows of @p width pixels in cairo's RGB24 layout (one native 32-bit
/// word 0x00RRGGBB per pixel, rows @p stride bytes apart); "" when libpng fails or memory runs out.
/// @pre pixels holds height * stride bytes, stride >= 4 * width.
[[nodiscard]] std::string encode_rgb24_png(const unsigned char* pixels, int stride,
                                           std::uint32_t width, std::uint32_t height);

}  // namespace orthoflow::ui
