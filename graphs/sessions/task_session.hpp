#pragma once
/// @file
/// @brief (internal) The closed loop of run_table_task (graphs/sessions/table_task_session.hpp) as
/// one object, shared by its parts: table_task_session.cpp (the world, the arm and the graph built,
/// and the run), table_task_frames.cpp (each frame: the stages, the arm's cycles, the events),
/// table_task_report.cpp (the report, held against the world's ground truth). Not thread-safe:
/// the graph's one source thread calls next_frame() in lock step.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "core/rng.hpp"
#include "drivers/jaco/jaco_controller.hpp"
#include "engine/object_list_payload.hpp"
#include "graphs/nodes/objects_output.hpp"
#include "graphs/nodes/world_source.hpp"
#include "graphs/services/arm_state_feed.hpp"
#include "graphs/services/learning_service.hpp"
#include "graphs/sessions/table_task_session.hpp"
#include "kernels/capsule_mask.hpp"
#include "manipulation/arm_body.hpp"
#include "manipulation/pick_place_job.hpp"
#include "manipulation/table_task_runner.hpp"
#include "simulation/devices/sim_jaco_transport.hpp"
#include "simulation/world/synthetic_scene.hpp"
#include "simulation/world/table_world.hpp"

namespace orthoflow::graphs {

namespace jaco = drivers::jaco;
using Eigen::Isometry3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using manipulation::Phase;

/// @brief The simulated clock when the loop starts (the arm is opened then).
inline constexpr std::int64_t TASK_LOOP_START_NS = 1'000'000'000;  // frame stamps must not be 0

/// @brief One run_table_task: the world, the simulated arm, the graph and the task runner.
class TaskLoop final : public WorldFeed {
 public:
  explicit TaskLoop(const TableTaskConfig& config) : config_(config) {}

  Result<TableTaskReport, std::string> run();
  const simulation::Scene* next_frame(kernels::PointCloud& cloud) noexcept override;

 private:
  enum class Stage { SETTLE, TEACH, RECOGNISE, TASK, FINISH, END };

  Result<void, std::string> build_world();
  /// The seeded table: make_scene's objects on the robot frames' table, clear of the arm's base
  /// column and of the placing area / the user's place, up to config_.objects.
  [[nodiscard]] simulation::Scene draw_scene(std::uint64_t seed);
  Result<void, std::string> open_arm();
  void make_runner();
  void take_objects() noexcept;
  void advance_stage();
  void teach();
  void plan_task();
  /// The world's object under the move's target (ground truth, to check where it ends up).
  void move_started(std::size_t move, const manipulation::SeenObject& s);
  void move_ended(std::size_t move);
  void arm_cycle() noexcept;
  void fire_event();
  void copy_records();
  void grow_reports();
  [[nodiscard]] std::string truth_near(const Vector3d& base_point) const;
  [[nodiscard]] std::int64_t now() const noexcept { return sim_.clock().now_ns(); }
  [[nodiscard]] Vector3d to_base(const simulation::Vec3& p) const {
    return base_from_camera_ * Vector3d(p[0], p[1], p[2]);
  }
  [[nodiscard]] bool submit(const jaco::ArmCommand& c) { return arm_->submit(c).has_value(); }

  TableTaskConfig config_;
  TableTaskReport report_;
  // The simulator's true camera pose (the world, its render, the report's ground truth) and the
  // one the robot believes (perception's objects, the grasps, the body filter): a calibration's.
  Isometry3d base_from_camera_ = Isometry3d::Identity();
  Isometry3d camera_from_base_ = Isometry3d::Identity();
  Isometry3d robot_base_from_camera_ = Isometry3d::Identity();
  std::optional<simulation::TableWorld> world_;
  simulation::SimJacoTransport sim_;
  std::unique_ptr<jaco::JacoController> arm_;
  std::int64_t next_cycle_ns_ = 0;
  ArmStateChannel arm_states_;
  std::unique_ptr<LearningService> learning_;
  std::unique_ptr<LearningClient> teacher_;
  ObjectsHub hub_;
  std::unique_ptr<ObjectsSubscription> objects_;
  engine::ObjectListPayload list_{};
  std::vector<manipulation::SeenObject> seen_;
  core::Rng rng_{0};
  simulation::RenderOptions render_{};
  manipulation::JobOptions job_options_{};
  std::optional<manipulation::TableTaskRunner> runner_;
  manipulation::TableTaskRunner::Submit submit_;
  Stage stage_ = Stage::SETTLE;
  std::uint64_t frame_ = 0;
  std::uint64_t stage_frame_ = 0;
  std::size_t teaches_sent_ = 0, acks_ = 0;
  int target_object_ = -1;                    // world object id of the current move's target
  Vector3d target_start_ = Vector3d::Zero();  // the world's object centre at the move's start
  bool event_fired_ = false, perception_dead_ = false;
  std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES> capsules_{};
  std::array<kernels::Capsule, manipulation::ARM_BODY_CAPSULES> robot_capsules_{};
};

}  // namespace orthoflow::graphs
