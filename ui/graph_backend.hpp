#pragma once
/// @file
/// @brief GraphBackend: the web view's backend over a running tabletop graph. Objects come from an
/// ObjectsSubscription of the graph's ObjectsHub (the objects_output node copies each frame's list
/// into the subscription's ring without waiting; a thread here takes the newest into a
/// mutex-guarded copy), the memory from the learner's snapshot, latency from the engine's
/// telemetry; actions go through one LearningClient of the learning channel and wait for their
/// LearningAck. Nothing here runs on the frame path.
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "core/result.hpp"
#include "engine/object_list_payload.hpp"
#include "engine/telemetry.hpp"
#include "graphs/nodes/objects_output.hpp"
#include "graphs/services/learning_service.hpp"
#include "ui/backend_support.hpp"
#include "ui/camera_view.hpp"
#include "ui/ui_backend.hpp"

namespace orthoflow::ui {

/// @note Thread-safe. @pre destroyed before @p learning and @p hub (and before the engine whose
/// telemetry it reads).
class GraphBackend final : public UiBackend {
 public:
  /// @brief Connects to the learning channel and subscribes to the objects. Errors: no free
  /// learning client slot.
  [[nodiscard]] static Result<std::unique_ptr<GraphBackend>, std::string> open(
      graphs::LearningService& learning, graphs::ObjectsHub& hub);
  ~GraphBackend() override;
  GraphBackend(const GraphBackend&) = delete;
  GraphBackend& operator=(const GraphBackend&) = delete;

  /// @brief The engine telemetry to show (null: none). @pre outlives this backend or is reset.
  void set_telemetry(const engine::GraphStats* stats) noexcept { stats_.store(stats); }
  [[nodiscard]] UiSnapshot snapshot() const override;
  [[nodiscard]] UiAnswer submit(const UiAction& action, int timeout_ms) override;
  [[nodiscard]] bool durable() const noexcept override { return learning_.durable(); }
  /// @brief The newest camera image from the hub's tap with the newest objects drawn on it (the
  /// objects may be a frame or two younger than the image: the tap copies at most 5 images/s).
  [[nodiscard]] std::string camera_png() override;
  void want_camera() override;

 private:
  GraphBackend(graphs::LearningService& learning, std::unique_ptr<graphs::LearningClient> client,
               std::unique_ptr<graphs::ObjectsSubscription> objects, graphs::CameraTap& camera);
  [[nodiscard]] std::vector<ObjectView> snapshot_objects() const;
  [[nodiscard]] std::vector<ObjectView> objects_locked() const;  // @pre state_lock_ held
  void draw_camera();
  void poll_objects() noexcept;
  void add_telemetry(UiSnapshot& s) const;

  graphs::LearningService& learning_;
  std::unique_ptr<graphs::LearningClient> client_;
  std::unique_ptr<graphs::ObjectsSubscription> objects_;
  graphs::CameraTap& camera_;
  mutable std::mutex camera_lock_;
  graphs::CameraImage camera_image_;      // guarded by camera_lock_: the last image taken
  PinholeFit camera_fit_;                 // guarded by camera_lock_: its camera
  std::string camera_png_;                // guarded by camera_lock_: it drawn, with the objects
  std::uint64_t camera_taken_ = 0;        // poller thread only: the last image taken from the tap
  std::condition_variable camera_drawn_;  // notified when camera_png_ changes
  std::mutex client_lock_;  // LearningClient is thread-compatible: one action at a time
  mutable std::mutex state_lock_;
  std::unique_ptr<engine::ObjectListPayload> latest_;  // guarded by state_lock_
  bool have_latest_ = false;                           // guarded by state_lock_
  EventLog events_;
  std::atomic<const engine::GraphStats*> stats_{nullptr};
  std::atomic<bool> stop_{false};
  std::thread poller_;
};

}  // namespace orthoflow::ui
