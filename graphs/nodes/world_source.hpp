#pragma once
/// @file
/// @brief The `world_source` node kind: frames of a closed-loop simulated world (issue 21, item 6),
/// produced by a WorldFeed that the process supplies (`orthoflow demo`: the table, the simulated
/// JACO and the task; graphs/sessions/table_task_session.hpp). The feed advances its world to the
/// next frame's time and renders it; the source stamps nothing itself (the feed's clock is the
/// frames' clock) and writes the frame's ground truth as synthetic_source does. Run with one frame
/// in flight, the feed sees every frame's objects before it renders the next: a lock-step loop.
#include <cstdint>

#include "engine/registry.hpp"
#include "kernels/point_cloud.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::graphs {

/// @brief What a world_source asks for each frame.
class WorldFeed {
 public:
  virtual ~WorldFeed() = default;
  /// @brief Advances the world to its next frame and renders it into @p cloud (host_stamp_ns set
  /// on the feed's clock). @return the scene rendered (its objects are the frame's ground truth),
  /// or null when the world has ended.
  [[nodiscard]] virtual const simulation::Scene* next_frame(
      kernels::PointCloud& cloud) noexcept = 0;
};

/// @brief Registers `world_source` (no parameters), bound to @p feed (null: the kind refuses).
void add_world_source_node(engine::NodeRegistry& registry, WorldFeed* feed);

}  // namespace orthoflow::graphs
