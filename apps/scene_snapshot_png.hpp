#pragma once
/// @file
/// @brief Draws a SceneSnapshot from above (table-plane coordinates): the table polygon, the object
/// points, each object's label and track id, and the X (red) and Y (green) axes of its GOOD frame.
#include <string>

#include "core/result.hpp"
#include "graphs/services/session_log.hpp"

namespace orthoflow::apps {

/// @brief Writes the picture as PNG to @p path. Errors name the file.
[[nodiscard]] Result<void, std::string> write_scene_snapshot_png(
    const graphs::SceneSnapshot& snapshot, const std::string& path);

}  // namespace orthoflow::apps
