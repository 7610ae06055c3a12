#pragma once
/// @file
/// @brief The closed loop of issue 21 (items 5-7): the thesis's clear_table and serve_a_meal
/// (chapter 8) run end to end on the simulators. One call builds
///   - a seeded tabletop (simulation::TableWorld, which reacts to the gripper),
///   - the simulated JACO behind its real driver (drivers::jaco::JacoController on
///     simulation::SimJacoTransport, on simulated time),
///   - the tabletop graph with its source swapped for a `world_source` and the robot-body filter
///     fed in-process by the arm's state (state: channel),
///   - an in-memory learner taught through the learning channel, as a person would (by position,
///     each object once, with its category),
///   - the task planned from the labels the learner gives (manipulation/table_tasks.hpp), each move
///     a grasp (manipulation/grasp_planner.hpp) and a pick-and-place job run by the execution
///     manager (manipulation/execution_manager.hpp) on perception's newest objects,
/// and runs it in lock step: one frame in flight; between frames the world, the arm (100 Hz) and
/// the manager advance by one frame period of simulated time. Same seed, same report.
///
/// The task refuses a category nobody taught; an arm fault, the emergency stop or an abort while
/// holding stops the whole task; any other abort fails that move and the task goes on.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "manipulation/execution_manager.hpp"
#include "manipulation/table_task_runner.hpp"
#include "manipulation/table_tasks.hpp"
#include "simulation/world/object_catalog.hpp"
#include "simulation/world/synthetic_scene.hpp"

namespace orthoflow::graphs {

using TableTask = manipulation::TableTaskKind;

/// @brief Trouble a script makes during one move (the aborts).
enum class TaskEvent : std::uint8_t {
  NONE,
  MOVE_TARGET,      ///< a person moves the target 10 cm along the table
  STOP_PERCEPTION,  ///< the objects stop arriving (perception died)
  UNPLUG_ARM,       ///< the arm's USB cable is pulled
};
[[nodiscard]] const char* to_string(TaskEvent event) noexcept;

/// @brief What on_frame sees.
struct TaskFrameView {
  std::uint64_t frame = 0;
  double seconds = 0.0;                      ///< simulated time since the start
  const simulation::Scene* scene = nullptr;  ///< objects where they are, the arm's capsules
  const Eigen::Isometry3d* base_from_camera = nullptr;
  int held_object_id = -1;  ///< world object id in the hand, or -1
  const char* phase = "";   ///< the execution manager's phase
};

struct TableTaskConfig {
  TableTask task = TableTask::CLEAR_TABLE;
  std::uint64_t seed = 1;
  std::uint32_t objects = 5;  ///< objects on the table (fewer if they do not fit)
  /// The scene's categories (empty: bottle, bowl, mug, can, box, flask, plate).
  std::vector<simulation::Category> categories;
  std::vector<std::string> keep{"plate"};  ///< clear_table: table items, they stay
  std::vector<std::string> bring;          ///< serve_a_meal: categories to bring, in order
  manipulation::TableArea area{{0.20, -0.50}, {0.56, -0.15}};  ///< clear_table: base frame (m)
  Eigen::Vector2d user_place{-0.35, -0.50};    ///< serve_a_meal: the first object's spot
  std::int64_t frame_period_ns = 100'000'000;  ///< the camera's period in simulated time
  std::uint32_t settle_frames = 10;            ///< frames before the person teaches (tracks form)
  std::uint32_t recognise_frames = 10;         ///< frames between the teaching and the plan
  double max_seconds = 900.0;                  ///< simulated time limit of the whole task
  TaskEvent event = TaskEvent::NONE;
  manipulation::Phase event_phase = manipulation::Phase::APPROACH;  ///< of the first move
  manipulation::ExecutionLimits limits = default_limits();
  /// The camera's pose in the arm's base frame as the robot believes it: a hand-eye calibration
  /// (`orthoflow calibrate ...`, `orthoflow demo --robot-frames`). Perception's objects, the grasps
  /// and the body filter use it; the world keeps the simulator's true pose. nullopt: the truth.
  std::optional<Eigen::Isometry3d> robot_base_from_camera;
  /// Called after every frame's objects arrived (the picture sequence); may be empty.
  std::function<void(const TaskFrameView&)> on_frame;

  /// @brief The manager's limits for this loop: a target unseen for 5 s (not counting while the
  /// hand hides it) is lost, one 6 cm from its plan has moved (a partial view's box shifts by a few
  /// centimetres), obstacles need 2 cm of clearance (they are covered by small spheres,
  /// manipulation::cover_box), and the slow phases near the table (approach, lift, place, retreat
  /// at 0.3 of the speed cap) get 20 s.
  [[nodiscard]] static manipulation::ExecutionLimits default_limits() noexcept;
};

using manipulation::OperatorTime;

/// @brief A move as the runner recorded it, and what the world says of it (ground truth).
struct MoveReport : manipulation::MoveRecord {
  std::string truth;  ///< the world's category of the object perceived there ("" if none)
  /// The world's object rests on the table, moved as planned within 5 cm: its displacement is the
  /// spot minus its perceived centre (ground truth, what a person watching would judge).
  bool arrived = false;
  double error_m = -1.0;  ///< that displacement's error (m); -1 when it was not moved
  bool held = false;      ///< the world's object was in the hand at some point (ground truth)
  /// The held object's worst tilt from upright during the move, at every arm cycle (ground truth).
  double max_tilt_deg = 0.0;
  bool spilled = false;  ///< an open container tilted past simulation::SPILL_TILT_DEG
  bool dropped = false;  ///< it slipped out of the hand, tilted past simulation::DROP_TILT_DEG
};

struct StayReport {
  std::uint32_t track = 0;
  std::string label;
  std::string truth;
  std::string reason;
};

struct TableTaskReport {
  std::string task;
  std::uint64_t seed = 0;
  std::vector<std::string> scene;  ///< the world's objects' categories at the start
  std::size_t taught = 0;          ///< teaches the learner acknowledged
  std::size_t recognised = 0;      ///< objects whose label at planning time equals their truth
  std::size_t perceived = 0;       ///< described objects at planning time
  std::string refused;             ///< why the task was refused before it started
  std::string stopped;             ///< why the task stopped before its last move
  std::vector<MoveReport> moves;
  std::vector<StayReport> stays;
  std::uint64_t frames = 0;
  double seconds = 0.0;             ///< simulated
  std::uint64_t body_dropped = 0;   ///< frames the body filter dropped (no fresh arm state)
  std::size_t fallen = 0;           ///< objects that fell off the table
  std::size_t spills = 0;           ///< carries in which an open container spilled
  std::size_t drops = 0;            ///< objects that slipped out of the hand, tilted
  bool calibrated = false;          ///< the robot used a calibration, not the simulator's truth
  double hand_eye_error_mm = 0.0;   ///< that calibration's translation error against the truth
  double hand_eye_error_deg = 0.0;  ///< and its rotation error (angle of R_used^T R_true)
  [[nodiscard]] std::size_t arrived() const noexcept;
  /// @brief Moves of the first pass: the objects the task moves (the rest are retries).
  [[nodiscard]] std::size_t first_moves() const noexcept;
};

/// @brief Runs one task. @return the report, or why the loop could not be built (a graph error).
[[nodiscard]] Result<TableTaskReport, std::string> run_table_task(const TableTaskConfig& config);

/// @brief The seeded table of a task: simulation::make_scene's objects on the synthetic table the
/// robot frames describe, standing on it, clear of the arm's base column (0.3 m) and of the placing
/// area (clear_table) or the user's place (serve_a_meal), up to config.objects; ids 0, 1, ...
[[nodiscard]] simulation::Scene draw_task_table(const TableTaskConfig& config, std::uint64_t seed);

/// @brief The camera pose the synthetic table implies (the arm's base on the table, 0.283 m
/// beyond its centre, its z up, its y away from the camera): config/robot_frames_synthetic.yaml.
[[nodiscard]] Eigen::Isometry3d synthetic_base_from_camera(const simulation::TableSpec& table);

}  // namespace orthoflow::graphs
