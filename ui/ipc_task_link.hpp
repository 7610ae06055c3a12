#pragma once
/// @file
/// @brief IpcTaskLink: the web view's link to `orthoflow task run` over iceoryx: commands out on
/// orthoflow/<graph>/task_commands, the task's state in on .../task_status
/// (graphs/channels/task_payloads.hpp), the same channel `orthoflow task start|stop|status` uses. A
/// thread here keeps the newest status; a send waits for the status that answers its own command
/// (the link's random client id and the command's number).
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "core/result.hpp"
#include "ui/task_link.hpp"

namespace orthoflow::engine {
class IpcPublisher;
class IpcSubscriber;
}  // namespace orthoflow::engine

namespace orthoflow::ui {

/// @note Thread-safe.
class IpcTaskLink final : public TaskLink {
 public:
  /// @brief Subscribes to graph @p graph's task status and offers its command topic. @pre the
  /// process's iceoryx runtime is initialised. Errors: iceoryx refused, RouDi's pools lack a chunk.
  [[nodiscard]] static Result<std::unique_ptr<IpcTaskLink>, std::string> open(
      const std::string& graph);
  ~IpcTaskLink() override;
  IpcTaskLink(const IpcTaskLink&) = delete;
  IpcTaskLink& operator=(const IpcTaskLink&) = delete;

  [[nodiscard]] std::optional<TaskView> view() const override;
  /// @brief NO_TASK_PROCESS at once when nobody subscribes to the command topic.
  [[nodiscard]] TaskReply send(const graphs::TaskCommand& command, int timeout_ms) override;
  /// @brief Over orthoflow/jaco/stop (any holder), reason "web view".
  [[nodiscard]] ArmStopReply stop_arm(int timeout_ms) override;
  /// @brief Status payloads that failed decoding (never shown).
  [[nodiscard]] std::uint64_t rejected() const noexcept { return rejected_.load(); }

 private:
  IpcTaskLink(std::unique_ptr<engine::IpcSubscriber> status,
              std::unique_ptr<engine::IpcPublisher> commands);
  void poll() noexcept;

  std::unique_ptr<engine::IpcSubscriber> status_in_;
  std::unique_ptr<engine::IpcPublisher> commands_out_;  // guarded by send_lock_
  std::mutex send_lock_;
  std::uint64_t client_id_ = 0;
  std::uint64_t next_request_ = 1;  // guarded by send_lock_
  mutable std::mutex state_lock_;
  std::optional<graphs::TaskStatus> newest_;  // guarded by state_lock_
  std::int64_t newest_at_ns_ = 0;             // guarded by state_lock_: arrival
  std::condition_variable arrived_;
  std::atomic<std::uint64_t> rejected_{0};
  std::atomic<bool> stop_{false};
  std::thread poller_;
};

}  // namespace orthoflow::ui
