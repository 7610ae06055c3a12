#pragma once
/// @file
/// @brief What the web view's server needs from the robot, as a small interface: a snapshot of the
/// state to show, and a way to submit an action and get its acknowledgement. GraphBackend
/// (ui/graph_backend.hpp) implements it over a running graph; tests may implement it over anything.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "graphs/channels/learning_channel.hpp"
#include "graphs/channels/task_payloads.hpp"

namespace orthoflow::ui {

class TaskLink;  // ui/task_link.hpp

/// @brief One object of the latest frame.
struct ObjectView {
  std::uint64_t track_id = 0;
  std::string label;  ///< "" when Unknown
  bool unknown = true;
  float score = 0.0F;
  float centroid[3] = {};  ///< sensor frame, metres
  float bbox_min[3] = {};  ///< axis-aligned box, sensor frame, metres
  float bbox_max[3] = {};
  std::uint32_t point_count = 0;
  std::uint32_t flags = 0;  ///< engine::OBJECT_* bits
};

/// @brief One category of the memory.
struct CategoryView {
  std::string label;
  std::size_t views = 0;
  std::int64_t last_taught_ms = 0;  ///< Unix time of the last teach / correct seen; 0 = not seen
};

/// @brief One action and its acknowledgement, for the recent-events list.
struct EventView {
  std::uint64_t id = 0;      ///< 1, 2, ... in the order the actions were answered
  std::int64_t time_ms = 0;  ///< Unix time of the answer
  std::string action;        ///< "teach", "correct", "ask", "forget"
  std::uint32_t track = 0;
  std::string label;    ///< what was sent (ask: the answer)
  std::string outcome;  ///< "stored", "learned", ..., or "timeout" / "queue_full"
  bool ok = false;
  std::uint32_t views = 0;
  std::uint64_t frame_id = 0;  ///< the frame that handled it
};

/// @brief One node's counters from the engine's telemetry.
struct NodeLatency {
  std::string name;
  std::uint64_t processed = 0, dropped = 0, deadline_misses = 0;
  std::int64_t p50_ns = 0, p99_ns = 0, max_ns = 0;
};

/// @brief Where the objects are in the camera image (ui/camera_view.hpp), for a click on it.
struct CameraBoxes {
  std::uint64_t frame_id = 0;           ///< of the image; 0 = no camera image
  std::uint32_t width = 0, height = 0;  ///< image pixels
  struct Box {
    std::uint64_t track = 0;
    float u0 = 0, v0 = 0, u1 = 0, v1 = 0;
  };
  std::vector<Box> boxes;
};

/// @brief Everything the page shows, copied out (the server never reads graph memory directly).
struct UiSnapshot {
  std::uint64_t frame_id = 0;  ///< of the objects; 0 before the first frame
  std::int64_t age_ns = 0;     ///< that frame's age at decision
  /// That frame's table verdict and where its up came from, as ObjectListPayload carries them
  /// (kernels::TableReason + 1 and graphs::Gravity + 1; 0: not reported).
  std::uint8_t table_reason = 0, gravity = 0;
  std::vector<ObjectView> objects;
  std::vector<CategoryView> memory;
  std::vector<EventView> events;  ///< oldest first
  std::vector<NodeLatency> nodes;
  std::uint64_t frames_done = 0, drops = 0;
  std::int64_t frame_p99_ns = 0;
  bool durable = false;  ///< acknowledged actions are on disk (--db)
  CameraBoxes camera;    ///< the objects in the last camera image served
  /// The table tasks (ui/task_link.hpp): whether the server can send task commands, and the task
  /// process's newest state (none when no task process published one lately).
  bool task_control = false;
  std::optional<graphs::TaskStatus> task;
  std::int64_t task_age_ms = 0;
};

/// @brief An action for the learning channel.
struct UiAction {
  graphs::LearningCommand::Kind kind = graphs::LearningCommand::Kind::TEACH;
  std::uint32_t track = 0;
  core::Text label;
};

/// @brief What became of an action.
struct UiAnswer {
  enum class Status : std::uint8_t {
    ACKNOWLEDGED,  ///< ack holds the learning channel's answer
    QUEUE_FULL,    ///< the command queue was full: nothing was sent
    TIMEOUT,       ///< no acknowledgement within the timeout (the graph may have stopped)
  };
  Status status = Status::TIMEOUT;
  graphs::LearningAck ack;
};

/// @brief The server's view of the robot. @note Implementations are thread-safe: the server calls
/// them from several threads at once.
class UiBackend {
 public:
  virtual ~UiBackend() = default;
  /// @brief A copy of the current state (off the frame path: allocates).
  [[nodiscard]] virtual UiSnapshot snapshot() const = 0;
  /// @brief Sends @p action and waits at most @p timeout_ms for its acknowledgement.
  [[nodiscard]] virtual UiAnswer submit(const UiAction& action, int timeout_ms) = 0;
  /// @brief Whether an acknowledged action is on disk (a durable memory, `--db`).
  [[nodiscard]] virtual bool durable() const noexcept { return false; }
  /// @brief The camera image with the objects drawn on it, as a PNG; "" when there is none (no
  /// frame yet, or a source without a pixel grid). Asking keeps the images coming for a while.
  [[nodiscard]] virtual std::string camera_png() { return {}; }
  /// @brief A viewer shows the camera image: keep drawing images for a while (the stream calls it
  /// for its clients that asked for the camera, so that the state says when an image is there
  /// before the page asks for one).
  virtual void want_camera() {}
  /// @brief The link to the process that runs the table tasks (ui/task_link.hpp), or null: set
  /// once, before serving; not owned.
  void set_task_link(TaskLink* link) noexcept { task_link_ = link; }
  [[nodiscard]] TaskLink* task_link() const noexcept { return task_link_; }

 private:
  TaskLink* task_link_ = nullptr;
};

}  // namespace orthoflow::ui
