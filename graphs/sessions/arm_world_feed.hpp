#pragma once
/// @file
/// @brief ArmWorldFeed: the closed-loop simulated world of issue 21 for a graph in its own process
/// (`orthoflow run --source world:SEED`), reacting to an arm in another process: the seeded table
/// of a task (draw_task_table), the arm's links rendered into the simulated Kinect's frames, and
/// the world's contact rule (simulation/world/table_world.hpp) applied to every arm state the arm
/// streams on `orthoflow/jaco/state` (the JACO behind `orthoflow task run --sim`, or `orthoflow arm
/// state
/// --publish`). The hardware-free stand-in for a camera looking at a real table with a real arm:
/// `orthoflow task run` then picks and places across processes exactly as on the robot.
///
/// Frames are stamped on the host's steady clock (the arm states' clock) when the world is taken,
/// before the render: the time of the arm pose drawn, which the body filter looks up. The graph's
/// rate paces them. Without any arm state yet, the world is rendered without the arm.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "core/rng.hpp"
#include "graphs/nodes/world_source.hpp"
#include "graphs/services/arm_state_feed.hpp"
#include "simulation/world/table_world.hpp"

namespace orthoflow::graphs {

/// @brief What happened to the world so far (ground truth, for a run's summary).
struct WorldTally {
  std::size_t objects = 0;
  std::size_t moved = 0;   ///< objects now more than 5 cm from where they started (along the table)
  std::size_t fallen = 0;  ///< off the table
  std::uint64_t frames = 0;
  std::uint64_t arm_states = 0;  ///< arm states applied
};

class ArmWorldFeed final : public WorldFeed {
 public:
  /// @brief The world of seed @p seed (clear_table's table: 5 objects, the placing area empty),
  /// following the arm states of @p state_topic, for @p frames frames (0: until stopped).
  /// @pre the process's iceoryx runtime is initialised. Errors: the topic cannot be subscribed.
  [[nodiscard]] static Result<std::unique_ptr<ArmWorldFeed>, std::string> create(
      std::uint64_t seed, const std::string& state_topic, std::uint64_t frames);

  const simulation::Scene* next_frame(kernels::PointCloud& cloud) noexcept override;
  /// @brief The tally; call when the graph has stopped (not thread-safe against next_frame).
  [[nodiscard]] WorldTally tally() const;

 private:
  ArmWorldFeed(simulation::Scene scene, std::unique_ptr<IpcArmStateFeed> states, std::uint64_t seed,
               std::uint64_t frames);

  simulation::TableWorld world_;
  std::unique_ptr<IpcArmStateFeed> states_;
  Eigen::Isometry3d base_from_camera_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d camera_from_base_ = Eigen::Isometry3d::Identity();
  std::vector<simulation::Vec3> start_;  ///< each object's centre at the start (sensor frame)
  std::array<engine::ArmStatePayload, 64> drained_{};
  std::optional<drivers::jaco::JointAngles> joints_;  ///< the newest arm state's
  core::Rng rng_;
  simulation::RenderOptions render_{};
  std::uint64_t frames_limit_ = 0;
  std::uint64_t frame_ = 0;
  std::uint64_t applied_ = 0;
};

}  // namespace orthoflow::graphs
