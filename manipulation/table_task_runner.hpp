#pragma once
/// @file
/// @brief TableTaskRunner: one of the thesis's table tasks (chapter 8) run on an arm from
/// perception's newest objects, move after move. The same runner drives the simulated robot of
/// `orthoflow demo` and a live arm under `orthoflow task run` (docs/MANIPULATION.md section 5).
///
/// What it does, from the moment start() plans the task (table_tasks.hpp) on the newest objects:
/// - for each move, finds the object again (by track, else nearby), plans its grasp
///   (grasp_planner.hpp) and searches a pick-and-place job (pick_place_job.hpp) whose every move
///   keeps clear of the other objects: grasps x lift heights x the spots of the moves still to come
///   (spots swap; packed places only when each object fits the other's), with a 2 cm planning
///   margin first, then without;
/// - runs the job with the execution manager (execution_manager.hpp) every arm cycle, feeding it
///   the target (not when the hand or the arm hides it: a cut view is no evidence) and the other
///   objects as obstacles;
/// - between jobs, parks the arm at its initial pose when the next object is unseen or hidden by
///   the arm, and looks for it again for a while;
/// - says what the hand holds (held()), for the arm-state stream that the robot-body filter reads;
/// - stops the task when the arm faults, the emergency stop is pulled, the arm refuses a command,
///   a move aborts while holding, or someone asks it to (request_stop()).
///
/// The caller owns the arm and the clock: it calls on_objects() for every object list, step()
/// once per perception frame, cycle() every arm cycle (100 Hz) and finish_step() after them.
/// Not thread-safe: one thread calls everything. Planning allocates (it is not the frame path of
/// the perception graph); cycle() does not.
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/result.hpp"
#include "drivers/jaco/jaco_controller.hpp"
#include "kernels/capsule_mask.hpp"
#include "manipulation/arm_body.hpp"
#include "manipulation/execution_manager.hpp"
#include "manipulation/pick_place_job.hpp"
#include "manipulation/table_tasks.hpp"

namespace orthoflow::manipulation {

/// @brief Most objects a task sees at once (engine::OBJECT_LIST_CAPACITY: one object list).
inline constexpr std::size_t MAX_TASK_OBJECTS = 64;

enum class TableTaskKind : std::uint8_t { CLEAR_TABLE, SERVE_A_MEAL };
/// @brief "clear_table" or "serve_a_meal".
[[nodiscard]] const char* to_string(TableTaskKind task) noexcept;
/// @brief The task named @p name ("clear_table", "serve_a_meal"; also with '-'), if any.
[[nodiscard]] bool parse_table_task(const std::string& name, TableTaskKind& out) noexcept;

/// @brief One perceived object in the arm's base frame (described: it has a box).
struct SeenObject {
  std::uint32_t track = 0;
  std::string label;  ///< empty: Unknown
  ObjectBox box;      ///< upright (upright_box) on the table
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

struct TableTaskOptions {
  TableTaskKind task = TableTaskKind::CLEAR_TABLE;
  std::vector<std::string> keep{"plate"};        ///< clear_table: table items, they stay
  std::vector<std::string> bring;                ///< serve_a_meal: categories to bring, in order
  TableArea area{{0.20, -0.50}, {0.56, -0.15}};  ///< clear_table: the placing area (base frame, m)
  Eigen::Vector2d user_place{-0.35, -0.50};      ///< serve_a_meal: the first object's spot
  ExecutionLimits limits{};
  JobOptions job{};  ///< the grasp planner's table, the initial pose, ...
  /// The camera in the arm's base frame (the robot frames): the arm's occlusion of an object is
  /// judged from the camera.
  Eigen::Isometry3d base_from_camera = Eigen::Isometry3d::Identity();
  /// A move whose object is unseen (or hidden by the arm) waits this many perception frames for it
  /// before it fails ("the object is no longer seen").
  std::uint32_t look_again_frames = 30;
  /// Once every move was tried, each one that failed (and did not stop the task) is tried once
  /// more, to the same spot: the objects moved since may have cleared its way.
  bool retry_failed = true;
};

struct OperatorTime {
  std::string phase;
  double seconds = 0.0;
};

/// @brief One move as it went.
struct MoveRecord {
  std::uint32_t track = 0;
  std::string label;  ///< the learner's
  Eigen::Vector2d to = Eigen::Vector2d::Zero();
  std::string grasp;  ///< "top" / "side", or "" when none was planned
  std::vector<OperatorTime> operators;
  bool done = false;    ///< the execution manager finished the move
  std::string failure;  ///< why not (an abort's reason, a planning refusal, ...)
  double seconds = 0.0;
  std::vector<std::string> decisions;  ///< the manager's log: "t phase -> phase: why"
  std::uint32_t attempt = 1;           ///< 2: the retry of a failed move (retry_of says which)
  std::size_t retry_of = 0;
};

/// @brief An object the task leaves where it is, and why.
struct StayRecord {
  std::uint32_t track = 0;
  std::string label;
  std::string reason;
};

class TableTaskRunner {
 public:
  enum class State : std::uint8_t {
    IDLE,      ///< not started
    MOVING,    ///< between jobs: planning the next move, parking or looking for its object
    RUNNING,   ///< a job runs
    FINISHED,  ///< every move was tried, or the task stopped (stopped() says why)
  };
  /// @brief Where the caller's arm takes commands: true if accepted.
  using Submit = std::function<bool(const drivers::jaco::ArmCommand&)>;

  explicit TableTaskRunner(TableTaskOptions options);

  /// @brief The newest object list: its described objects in the base frame, and its stamp.
  void on_objects(std::span<const SeenObject> objects, std::int64_t stamp_ns);
  /// @brief The arm as the camera sees it at the newest frame (from its joints): for occlusion.
  void on_arm_pose(const drivers::jaco::JointAngles& joints) noexcept;
  /// @brief The same from the arm's capsules without margin (arm_body_capsules, margin 0) when the
  /// caller has them already (the demo renders them).
  void on_arm_body(std::span<const kernels::Capsule> body) noexcept;

  /// @brief Plans the task on the newest objects. @p known: the categories the learner knows
  /// (serve_a_meal refuses a category nobody taught). @return why the task cannot start.
  [[nodiscard]] Result<void, std::string> start(std::span<const std::string> known);
  /// @brief Once per perception frame: starts the next move when none runs (or parks the arm).
  void step(std::int64_t now_ns, const drivers::jaco::ArmSnapshot& arm, const Submit& submit);
  /// @brief Every arm cycle: the running job's decision, sent to the arm. @return true if the
  /// arm needs a keep-alive this cycle (a motion is under way).
  bool cycle(std::int64_t now_ns, const drivers::jaco::ArmSnapshot& arm, const Submit& submit);
  /// @brief After the cycles of a frame (or after each cycle): ends the move whose job has ended.
  void finish_step(std::int64_t now_ns);
  /// @brief A person stops the task: the running job backs away (or holds, as for any abort), a
  /// parking arm stops, no further move starts. @p why goes into stopped().
  void request_stop(std::int64_t now_ns, const std::string& why, const Submit& submit);
  /// @brief Stops the running job now and leaves the records as they are (a time limit).
  void halt(std::int64_t now_ns) noexcept;

  /// @brief True while the hand holds (or should hold) the target; @p out: its capsule.
  [[nodiscard]] bool held(HeldObject& out) const noexcept;

  [[nodiscard]] State state() const noexcept { return state_; }
  [[nodiscard]] const std::vector<MoveRecord>& moves() const noexcept { return moves_; }
  [[nodiscard]] const std::vector<StayRecord>& stays() const noexcept { return stays_; }
  /// @brief Each move's object centre when the task was planned (base frame).
  [[nodiscard]] const std::vector<Eigen::Vector3d>& planned() const noexcept { return planned_; }
  [[nodiscard]] std::size_t move_index() const noexcept { return move_; }
  [[nodiscard]] const std::string& stopped() const noexcept { return stopped_; }
  [[nodiscard]] const ExecutionManager& manager() const noexcept { return manager_; }
  /// @brief The running move's target centre at its start, and its spot.
  [[nodiscard]] const Eigen::Vector3d& target_centre() const noexcept { return target_centre_; }
  [[nodiscard]] const std::vector<SeenObject>& seen() const noexcept { return seen_; }
  [[nodiscard]] const TableTaskOptions& options() const noexcept { return options_; }

  /// Called when a move's job starts (its index and the object as seen), and when it ends.
  std::function<void(std::size_t, const SeenObject&)> on_move_started;
  std::function<void(std::size_t)> on_move_ended;

 private:
  void start_move(std::int64_t now_ns, const drivers::jaco::ArmSnapshot& arm, const Submit& submit);
  void finish_move(std::int64_t now_ns);
  /// After a move the manager calls done: if its object (its label) still stands where it was
  /// planned from, and not at its spot, the grasp missed it unseen (the hand hid the lift): the
  /// move is failed, so that it is retried. A view the arm cuts is no evidence either way.
  void check_left_behind(std::size_t move);
  void end_task(const std::string& why);
  /// Appends a retry of every failed move of the first pass. @return how many.
  std::size_t add_retries();
  bool park(const drivers::jaco::ArmSnapshot& arm, const Submit& submit);
  std::size_t fill_obstacles(const SeenObject* target, const Eigen::Vector3d& hand, bool holding);
  std::size_t add_spheres(const SeenObject& o, std::size_t used);
  [[nodiscard]] const SeenObject* find_seen(std::uint32_t track, const Eigen::Vector3d& near,
                                            const std::string& label, double same_label_m,
                                            double any_m, bool not_bystanders = false) const;
  /// True if an object at @p centre, standing, is nearer to where another object stood when the
  /// running move started than to where its target stood.
  [[nodiscard]] bool a_bystander(const Eigen::Vector3d& centre) const noexcept;
  [[nodiscard]] const SeenObject* current_target() const;
  [[nodiscard]] bool is_target(const SeenObject& o, const SeenObject* t) const;
  [[nodiscard]] bool placing() const noexcept;
  /// True if moves @p a and @p b may swap places: always on the grid's spots; when clear_table's
  /// places are packed by footprint, each object must fit the other's place beside everything else
  /// placed or to be placed.
  [[nodiscard]] bool spots_swap(std::size_t a, std::size_t b) const;
  [[nodiscard]] bool arm_hides(const Eigen::Vector3d& base_point, double radius_m) const noexcept;

  TableTaskOptions options_;
  Eigen::Isometry3d camera_from_base_ = Eigen::Isometry3d::Identity();
  State state_ = State::IDLE;
  std::vector<SeenObject> seen_;
  std::int64_t seen_stamp_ns_ = 0;
  std::vector<Obstacle> others_;
  /// Where the other objects stood when the running move started (base frame).
  std::array<Eigen::Vector3d, MAX_TASK_OBJECTS> bystanders_{};
  std::size_t bystander_count_ = 0;
  ExecutionManager manager_{};
  std::vector<MoveRecord> moves_;
  std::vector<StayRecord> stays_;
  std::vector<Eigen::Vector3d> planned_;
  std::vector<double> radii_;        ///< each move's footprint (its place was chosen for it)
  std::vector<Footprint> occupied_;  ///< clear_table: what stood in the area and stays
  bool packed_ = false;              ///< clear_table's places are packed by footprint
  double packed_gap_m_ = 0.0;        ///< and the gap the plan kept between them
  std::string stopped_;
  std::size_t move_ = 0;
  std::int64_t move_start_ns_ = 0;
  std::uint32_t target_track_ = 0;
  Eigen::Vector3d target_centre_ = Eigen::Vector3d::Zero();
  Eigen::Vector2d target_place_ = Eigen::Vector2d::Zero();
  std::string target_label_;
  HeldObject held_{};
  bool was_holding_ = false;
  bool parking_ = false;
  bool waiting_ = false;
  bool stop_requested_ = false;
  bool retried_ = false;
  std::uint32_t unseen_frames_ = 0;
  std::array<kernels::Capsule, ARM_BODY_CAPSULES> sight_{};
  std::size_t sight_count_ = 0;
};

}  // namespace orthoflow::manipulation
