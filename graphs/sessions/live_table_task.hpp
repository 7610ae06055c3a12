#pragma once
/// @file
/// @brief LiveTableTask: a table task on a live arm (issue 21, item 5), started and stopped by
/// commands (graphs/channels/task_payloads.hpp: the task command channel; `orthoflow task
/// start|stop`), run by manipulation::TableTaskRunner on the object lists of a running graph
/// (`orthoflow run --ipc-learning`), with the arm's state streamed back for the graph's robot-body
/// filter, what the hand holds included. `orthoflow task run` is this class on a JacoArm and
/// iceoryx; a test drives it in lock step with the simulated JACO.
///
/// The caller owns the arm, the clock and the transport: it hands in every object list
/// (on_objects) and command (command, invalid) and calls tick() once per arm cycle (10 ms).
/// Everything runs on that one thread. The arm moves only by the runner's checked jobs; a stop
/// command makes the running job back away, as any abort does; a halt (a signal, a stop request:
/// the arm latched) ends the task where the arm stands.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "drivers/jaco/jaco_controller.hpp"
#include "engine/arm_state_payload.hpp"
#include "engine/object_list_payload.hpp"
#include "graphs/channels/task_payloads.hpp"
#include "manipulation/table_task_runner.hpp"

namespace orthoflow::graphs {

/// @brief The described objects of @p list in the arm's base frame (boxes upright on @p table),
/// into @p out (cleared first). An object whose frame or box is not finite, or whose box is not
/// within (0, 2 m), is left out; at most OBJECT_LIST_CAPACITY are read whatever the count says.
void seen_objects(const engine::ObjectListPayload& list, const Eigen::Isometry3d& base_from_camera,
                  const manipulation::SupportPlane& table,
                  std::vector<manipulation::SeenObject>& out);

/// @brief What the task talks to (set by the caller; publish_* and known may be empty).
struct LiveTaskPorts {
  std::function<drivers::jaco::ArmSnapshot()> snapshot;  ///< the arm's newest state
  manipulation::TableTaskRunner::Submit submit;          ///< a command to the arm: accepted?
  std::function<void()> keep_alive;                      ///< the arm's watchdog, during a motion
  std::function<void(const engine::ArmStatePayload&)> publish_state;  ///< every tick
  std::function<void(const TaskStatus&)> publish_status;  ///< after a command, and periodically
  std::function<std::vector<std::string>()> known;        ///< the categories the learner knows
};

struct LiveTaskSettings {
  /// Everything of a task but its kind and the categories to bring (those come with each start):
  /// placing area, table items, user's place, limits, job options, robot frames.
  manipulation::TableTaskOptions options{};
  std::int64_t fresh_objects_ns = 1'000'000'000;  ///< a start needs objects this new
  std::int64_t status_period_ns = 200'000'000;    ///< status at least this often
};

class LiveTableTask {
 public:
  LiveTableTask(LiveTaskSettings settings, LiveTaskPorts ports);

  /// @brief The graph's newest object list (camera frame; converted to the base frame here).
  void on_objects(const engine::ObjectListPayload& list);
  /// @brief A decoded command at @p now_ns: answered at once (the answer goes out in a status).
  TaskAnswer command(const RemoteTaskCommand& command, std::int64_t now_ns);
  /// @brief A command that failed validation: answered INVALID with its reason.
  void invalid(const TaskCommandProblem& problem, std::int64_t now_ns);
  /// @brief The arm was halted and latched (a signal, a stop request): the task ends where it is.
  /// The arm refuses motion while latched, so nothing backs away; @p why goes into the report.
  void halted(const std::string& why, std::int64_t now_ns);
  /// @brief One arm cycle at @p now_ns (the clock of the object lists' host stamps).
  void tick(std::int64_t now_ns);

  [[nodiscard]] TaskStatus status(std::int64_t now_ns) const;
  /// @brief The newest task's runner (nullptr before the first start).
  [[nodiscard]] const manipulation::TableTaskRunner* runner() const noexcept {
    return runner_ ? &*runner_ : nullptr;
  }
  /// @brief True while a task runs.
  [[nodiscard]] bool running() const noexcept;

 private:
  void answer(std::uint64_t client, std::uint64_t request, TaskAnswer a, std::string message,
              std::int64_t now_ns);
  void publish(std::int64_t now_ns);
  [[nodiscard]] TaskState status_state() const noexcept;

  LiveTaskSettings settings_;
  LiveTaskPorts ports_;
  std::vector<manipulation::SeenObject> seen_;
  std::int64_t seen_stamp_ns_ = 0;
  bool new_objects_ = false;
  std::optional<manipulation::TableTaskRunner> runner_;
  manipulation::TableTaskKind task_ = manipulation::TableTaskKind::CLEAR_TABLE;
  std::uint64_t client_ = 0, request_ = 0;
  TaskAnswer answer_ = TaskAnswer::NONE;
  std::string message_;
  std::int64_t last_status_ns_ = 0;
  TaskState published_state_ = TaskState::IDLE;
};

}  // namespace orthoflow::graphs
