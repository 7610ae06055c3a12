#pragma once
/// @file
/// @brief `orthoflow demo --pictures DIR`: the closed-loop world from above, in the arm's base
/// frame (x right, y away from the camera): the table, the placing area or the user's place, each
/// object's footprint named by its category (the one in the hand filled), and the arm's links.
#include <string>

#include "core/result.hpp"
#include "graphs/sessions/table_task_session.hpp"

namespace orthoflow::apps {

/// @brief What the picture marks besides the world.
struct DemoMarks {
  const manipulation::TableArea* area = nullptr;  ///< clear_table's placing area
  const Eigen::Vector2d* user_place = nullptr;    ///< serve_a_meal's first spot
};

/// @brief Writes @p view as a PNG to @p path. Errors name the file.
[[nodiscard]] Result<void, std::string> write_demo_picture(const graphs::TaskFrameView& view,
                                                           const DemoMarks& marks,
                                                           const std::string& path);

}  // namespace orthoflow::apps
